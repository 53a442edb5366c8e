"""A bug's 500 (issue 24): in the public shape, with the security headers every other answer
has, and ``Connection: close`` (the server drops the connection after it)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from opaline.server.api import create_app
from opaline.settings import Settings


@pytest.mark.gl
def test_a_crash_answers_500_with_security_headers_and_connection_close(backend):
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1))

    @app.get("/crash-for-test")
    async def crash() -> None:
        raise RuntimeError("a bug")

    with TestClient(app, raise_server_exceptions=False) as client:
        answer = client.get("/crash-for-test")
        assert answer.status_code == 500
        assert answer.json() == {"error": "error", "detail": [
            "internal error: the details are in the server log"]}
        assert answer.headers["x-content-type-options"] == "nosniff"
        assert answer.headers["referrer-policy"] == "no-referrer"
        assert answer.headers["connection"] == "close"
        fine = client.get("/healthz")  # an ordinary answer keeps the connection
        assert "close" not in fine.headers.get("connection", "")
        assert fine.headers["x-content-type-options"] == "nosniff"
