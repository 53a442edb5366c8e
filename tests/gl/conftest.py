"""Fixtures for the shader tests (test_shaders.py, test_variant_source.py)."""

from __future__ import annotations

import shutil

import pytest

from opaline import resources
from opaline.gl import shaders


@pytest.fixture
def glsl_copy(tmp_path, monkeypatch):
    """A private copy of glsl/ that shaders reads from; caches cleared on both sides."""
    root = tmp_path / "glsl"
    shutil.copytree(shaders.glsl_root(), root)
    monkeypatch.setattr(shaders, "glsl_root", lambda: root)
    monkeypatch.setattr(resources, "glsl_root", lambda: root)
    shaders.read_source.cache_clear()
    shaders.sources_digest.cache_clear()
    yield root
    shaders.read_source.cache_clear()
    shaders.sources_digest.cache_clear()
