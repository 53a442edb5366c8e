"""Access control (issue 11, part 2): API keys, signed GET URLs, rate limits."""

from __future__ import annotations

import time
from urllib.parse import parse_qsl, urlsplit

import pytest
from fastapi.testclient import TestClient

from opaline.server.access import RateLimiter
from opaline.server.api import create_app
from opaline.server.signing import sign_url, verify
from opaline.settings import Settings

KEY, SECRET = "k-3c1f9a0e5d", "s-81b2e7f44a"
SMALL = [("width", "32"), ("height", "32"), ("quality", "draft"), ("mu_f", "4.5")]


def signed(path: str = "/v1/render", params=SMALL, secret: str = SECRET, expires_at=None) -> str:
    return sign_url(secret.encode(), path, list(params), expires_at)


# The signature on its own


def test_signature_covers_path_values_order_and_expiry():
    url = signed(expires_at=int(time.time()) + 60)
    path, query = url.split("?")
    assert verify([SECRET.encode()], path, query) == (True, "")
    tampered = query.replace("mu_f=4.5", "mu_f=4.6")
    assert verify([SECRET.encode()], path, tampered)[0] is False
    assert verify([SECRET.encode()], "/v1/mdf", query)[0] is False
    assert verify([b"another secret"], path, query)[0] is False
    # A parameter's position does not matter, but albedo's R, G, B order does.
    params = parse_qsl(query)
    assert verify([SECRET.encode()], path, "&".join(f"{k}={v}" for k, v in reversed(params)))[0]
    rgb = signed(params=[("albedo", "0.1"), ("albedo", "0.2"), ("albedo", "0.3")])
    swapped = rgb.replace("albedo=0.1&albedo=0.2", "albedo=0.2&albedo=0.1")
    assert verify([SECRET.encode()], *swapped.split("?"))[0] is False
    expired = signed(expires_at=int(time.time()) - 1)
    assert verify([SECRET.encode()], *expired.split("?")) == (False, "this signed URL has expired")


def test_rate_limiter_refills_at_its_rate():
    now = [0.0]
    limiter = RateLimiter(rate=2.0, burst=3, clock=lambda: now[0])
    assert [limiter.wait_s("a") for _ in range(3)] == [0.0, 0.0, 0.0]
    assert limiter.wait_s("a") == pytest.approx(0.5)
    assert limiter.wait_s("b") == 0.0  # each identity has its own bucket
    now[0] = 0.5
    assert limiter.wait_s("a") == 0.0


# Through the app


@pytest.fixture(scope="module")
def client(backend):
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                        api_keys=f"old-key,{KEY}", signing_key=SECRET)
    with TestClient(create_app(settings)) as client:
        yield client


def forbidden(response) -> str:
    assert response.status_code == 403, response.text
    body = response.json()
    assert body["error"] == "forbidden"
    assert KEY not in response.text and SECRET not in response.text
    return body["detail"][0]


@pytest.mark.gl
def test_signed_urls_render_and_anything_else_is_403(client):
    url = signed(expires_at=int(time.time()) + 300)
    assert client.get(url).status_code == 200
    assert client.head(url).status_code == 200
    plain = url.split("&sig=")[0]
    assert "signed URL is required" in forbidden(client.get(plain))
    assert "does not match" in forbidden(client.get(url.replace("mu_f=4.5", "mu_f=9")))
    assert "does not match" in forbidden(client.get(signed(secret="guessed")))
    assert "expired" in forbidden(client.get(signed(expires_at=int(time.time()) - 5)))
    mdf = signed("/v1/mdf", [("size", "16")])
    assert client.get(mdf).status_code == 200
    # A signature does not open other routes or methods.
    forbidden(client.get("/v1/presets?" + urlsplit(url).query))
    forbidden(client.post(url, json={}))


@pytest.mark.gl
def test_api_key_opens_every_route_and_metrics(client):
    header = {"X-API-Key": KEY}
    query = "&".join(f"{k}={v}" for k, v in SMALL)
    assert client.get(f"/v1/render?{query}", headers=header).status_code == 200
    bearer = {"Authorization": f"Bearer {KEY}"}
    assert client.post("/v1/render", json={"width": 32, "height": 32, "quality": "draft"}, headers=bearer).status_code == 200
    assert client.get("/v1/presets", headers=header).status_code == 200
    assert client.get("/metrics", headers=header).status_code == 200
    assert "not valid" in forbidden(client.get("/metrics", headers={"X-API-Key": KEY + "x"}))
    forbidden(client.get("/metrics"))
    forbidden(client.get("/v1/presets"))


@pytest.mark.gl
def test_probes_page_and_docs_stay_open(client):
    for path in ("/healthz", "/readyz", "/", "/static/main.js", "/docs", "/openapi.json"):
        assert client.get(path).status_code == 200, path


@pytest.mark.gl
def test_rate_limit_answers_429_with_retry_after(backend):
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                        rate_limit_per_s=0.5, rate_burst=3)
    with TestClient(create_app(settings)) as client:
        page = [client.get(path).status_code for path in ("/", "/static/main.js",
                                                          "/static/api.js") * 3]
        assert page == [200] * 9  # the page and its files spend none of the budget
        answers = [client.get("/v1/presets") for _ in range(5)]
        assert [a.status_code for a in answers] == [200, 200, 200, 429, 429]
        assert answers[-1].json()["error"] == "rate_limited"
        assert int(answers[-1].headers["retry-after"]) >= 1
        assert client.get("/healthz").status_code == 200  # probes are never limited
