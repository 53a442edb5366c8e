"""The service under a real uvicorn process on loopback: bursts get 200 or 503, never a hang."""

from __future__ import annotations

import signal
from concurrent.futures import ThreadPoolExecutor

import httpx
import pytest

from opaline.server.localserver import LocalServer, ServerError

pytestmark = pytest.mark.gl

QUEUE = 2
BURST = 24  # distinct renders at once: far more than one worker and a queue of 2 hold
TIMEOUT = httpx.Timeout(30.0, connect=5.0)


@pytest.fixture(scope="module")
def server(backend):
    env = {"OPALINE_GL_BACKEND": backend, "OPALINE_QUEUE_SIZE": str(QUEUE),
           "OPALINE_DEADLINE_S": "30", "OPALINE_WARMUP": "false"}
    try:
        with LocalServer(workers=1, env=env) as local:
            yield local.base, local.proc, local.log
    except ServerError as exc:
        pytest.fail(str(exc))


def test_ready_over_http(server):
    """The real server answers /healthz and /readyz on loopback."""
    base, _, _ = server
    assert httpx.get(f"{base}/healthz", timeout=TIMEOUT).status_code == 200
    assert httpx.get(f"{base}/readyz", timeout=TIMEOUT).json()["ready"] is True


def test_burst_larger_than_queue_gets_200_or_503(server):
    """A burst of distinct renders beyond the queue: every answer is 200 or 503, none hangs."""
    base, _, _ = server
    limits = httpx.Limits(max_connections=BURST)
    with httpx.Client(base_url=base, timeout=TIMEOUT, limits=limits) as client:

        def ask(i: int) -> httpx.Response:
            return client.get(f"/v1/render?preset=cd-rom&quality=high&mu_f={1 + i / 10}")

        with ThreadPoolExecutor(BURST) as pool:
            answers = list(pool.map(ask, range(BURST), timeout=60))
    statuses = [a.status_code for a in answers]
    assert set(statuses) <= {200, 503}, statuses
    assert 200 in statuses and 503 in statuses, statuses
    assert all(a.headers.get("retry-after") for a in answers if a.status_code == 503)
    assert all(a.content.startswith(b"\x89PNG") for a in answers if a.status_code == 200)


def test_normal_request_succeeds_after_burst(server):
    """After the burst the server is idle again and renders normally."""
    base, _, _ = server
    response = httpx.get(f"{base}/v1/render?preset=sphere&width=64&height=64&quality=draft",
                         timeout=TIMEOUT)
    assert response.status_code == 200 and response.content.startswith(b"\x89PNG")
    assert httpx.get(f"{base}/readyz", timeout=TIMEOUT).json()["queue_depth"] == 0


def test_oversized_body_over_http(server):
    """A body over the limit gets 413 from the real server, which then keeps serving."""
    base, _, _ = server
    response = httpx.post(f"{base}/v1/render", content=b"{" + b" " * 100_000 + b"}",
                          headers={"content-type": "application/json"}, timeout=TIMEOUT)
    assert response.status_code == 413
    assert httpx.get(f"{base}/healthz", timeout=TIMEOUT).status_code == 200


def test_sigterm_stops_cleanly(server):
    """SIGTERM ends the server within seconds, without a traceback in its log."""
    _, proc, log = server
    proc.send_signal(signal.SIGTERM)
    # uvicorn shuts down gracefully, then re-raises the signal it caught
    assert proc.wait(15) in (0, -signal.SIGTERM)
    log.seek(0)
    assert "Traceback" not in log.read()
