"""One path per request: one resolve and one quality=auto pick per GET, and every entry
point renders quality=auto under an environment (a tier-name lookup used to crash it)."""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient

from opaline.cli import main as cli
from opaline.local.api import render
from opaline.model import auto, request
from opaline.server.api import create_app
from opaline.settings import Settings

PNG = b"\x89PNG\r\n\x1a\n"
AUTO_UNDER_STUDIO = {"preset": "sphere", "quality": "auto", "environment": "studio",
                     "width": 128, "height": 128}


@pytest.fixture
def calls(monkeypatch) -> Iterator[Counter[str]]:
    """How often ``resolve`` and ``pick`` run, however a module imported them."""
    counted: Counter[str] = Counter()

    def counting(name: str, original: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            counted[name] += 1
            return original(*args, **kwargs)
        return wrapper

    for name, original in (("resolve", request.resolve), ("pick", auto.pick)):
        wrapper = counting(name, original)
        for module in [m for key, m in sys.modules.items() if key.startswith("opaline")]:
            for attribute, value in list(vars(module).items()):
                if value is original:
                    monkeypatch.setattr(module, attribute, wrapper)
    yield counted


@pytest.fixture(scope="module")
def client(backend) -> Iterator[TestClient]:
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1)
    with TestClient(create_app(settings)) as client:
        yield client


def test_the_counter_sees_every_resolve(calls):
    """The count is not vacuous: a module that imported resolve by name is counted."""
    from opaline.cli import main as cli_main  # imports resolve by name

    cli_main.resolve(request.RenderRequest())
    assert calls["resolve"] == 1


@pytest.mark.gl
@pytest.mark.parametrize("query", ["preset=cd-rom&mu_f=3&width=64&height=64",
                                   "quality=auto&width=128&height=128&mu_f=9",
                                   "max_flip=0.1&width=128&height=128&theta1=-0.0"])
def test_a_get_resolves_once_and_picks_at_most_once(client, calls, query):
    """A plain GET resolves its request once (the canonical URL is read off the job), and
    quality=auto picks once."""
    response = client.get("/v1/render?" + query)
    assert response.status_code == 200, response.text
    assert calls["resolve"] == 1
    assert calls["pick"] == (0 if "width=64" in query else 1)


@pytest.mark.gl
def test_auto_with_an_environment_over_http(client):
    query = "&".join(f"{k}={v}" for k, v in AUTO_UNDER_STUDIO.items())
    response = client.get("/v1/render?" + query)
    assert response.status_code == 200, response.text
    assert response.content.startswith(PNG)
    assert "X-Opaline-Auto-Basis" in response.headers


@pytest.mark.gl
def test_auto_with_an_environment_in_python(backend):
    assert render(AUTO_UNDER_STUDIO, backend=backend).startswith(PNG)


@pytest.mark.gl
def test_auto_with_an_environment_on_the_cli(backend, tmp_path, capsys):
    out = tmp_path / "auto.png"
    code = cli.main(["render", "sphere", "--quality", "auto", "--size", "128",
                          "--set", "environment=studio", "--backend", backend, "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert out.read_bytes().startswith(PNG)
