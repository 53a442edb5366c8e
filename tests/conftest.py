"""Shared fixtures: one renderer per test session on the backend under test.

The backend comes from OPALINE_GL_BACKEND (egl by default); scripts/test runs
the GL tests a second time with OPALINE_GL_BACKEND=osmesa. Only one backend
lives in a process: EGL and OSMesa share Mesa's GL dispatch.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

from opaline.gl.context import requested_backend

# CI replays the same examples every run (a red CI must mean a change broke
# something); local runs keep exploring new ones, and pin what they find with
# @example.
settings.register_profile("ci", derandomize=True, database=None)
if os.environ.get("CI"):
    settings.load_profile("ci")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "gl: needs a headless GL context (run on both backends)")


@pytest.fixture(scope="session")
def backend() -> str:
    return requested_backend(os.environ.get("OPALINE_GL_BACKEND"))


@pytest.fixture(scope="session")
def renderer(backend):
    from opaline.gl.renderer import Renderer
    from opaline.settings import setting

    r = Renderer(backend, environments_dir=setting("environments_dir"), environment_paths=True)
    yield r
    r.release()


@pytest.fixture(scope="session")
def local(renderer):
    """A LocalRenderer sharing the session's context."""
    from opaline.local.pipeline import LocalRenderer

    local = LocalRenderer.__new__(LocalRenderer)
    local.renderer = renderer
    local.cost_budget = 2048 * 2048 * 64 * 3
    return local


@pytest.fixture
def shared_renderer(renderer, monkeypatch):
    """GL commands draw on the session's renderer instead of opening a context of their own.

    A second context made and released on this thread would leave the session's OSMesa
    context broken for every later GL test (see test_context's two-renderer test).
    """
    from opaline.local import pipeline

    class Shared(pipeline.LocalRenderer):
        def __init__(self, backend=None, cost_budget=None):
            self.renderer = renderer
            self.cost_budget = cost_budget

        def close(self) -> None:  # the session owns the context
            pass

    monkeypatch.setattr(pipeline, "LocalRenderer", Shared)


@pytest.fixture()
def cost_budget(monkeypatch):
    """Sets OPALINE_COST_BUDGET for one test (settings are read once, so the cache is reset)."""
    from opaline.settings import get_settings

    def set_budget(value: int) -> None:
        monkeypatch.setenv("OPALINE_COST_BUDGET", str(value))
        get_settings.cache_clear()

    yield set_budget
    monkeypatch.delenv("OPALINE_COST_BUDGET", raising=False)
    get_settings.cache_clear()
