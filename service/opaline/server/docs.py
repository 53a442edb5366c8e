"""The API documentation served by the service itself, and security headers on its pages.

FastAPI's /docs and /redoc load Swagger UI and ReDoc from a CDN, so they were
blank on an air-gapped machine or in the container. The assets here come from
the ``fastapi-offline`` package (Swagger UI 5) and are served under
/docs-assets. (ReDoc is left out: its sidebar loads a logo from cdn.redoc.ly
whatever its options.) Every HTML answer gets a Content-Security-Policy that allows only
this origin (the docs' one inline script by its hash), frame-ancestors 'none',
and every answer ``X-Content-Type-Options: nosniff`` and ``Referrer-Policy:
no-referrer`` (a signed URL must not leak to other sites through Referer).
"""

from __future__ import annotations

import base64
import hashlib
import re
from pathlib import Path

from fastapi import FastAPI
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import HTMLResponse
from fastapi.staticfiles import StaticFiles
from starlette.datastructures import MutableHeaders
from starlette.types import ASGIApp, Message, Receive, Scope, Send

ASSETS = "/docs-assets"
# The page (its ES modules) sets no inline script or style; images are blob: URLs of fetched answers
# (which a script may read back: connect-src blob:).
PAGE_CSP = ("default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' blob: data:; "
            "connect-src 'self' blob:; object-src 'none'; base-uri 'none'; form-action 'self'; "
            "frame-ancestors 'none'")
INLINE_SCRIPT = re.compile(rb"<script>(.*?)</script>", re.S)


def assets_dir() -> Path:
    import fastapi_offline

    return Path(fastapi_offline.__file__).resolve().parent / "static"


def docs_csp(html: bytes) -> str:
    """CSP for the docs page: its inline script by hash; Swagger UI sets inline styles."""
    hashes = " ".join("'sha256-" + base64.b64encode(hashlib.sha256(s).digest()).decode() + "'"
                      for s in INLINE_SCRIPT.findall(html))
    return (f"default-src 'self'; script-src 'self' {hashes}; style-src 'self' 'unsafe-inline'; "
            "img-src 'self' data:; connect-src 'self'; "
            "object-src 'none'; base-uri 'none'; frame-ancestors 'none'")


def _with_csp(page: HTMLResponse) -> HTMLResponse:
    page.headers["Content-Security-Policy"] = docs_csp(bytes(page.body))  # bytes already
    return page


def mount_docs(app: FastAPI) -> None:
    """/docs (Swagger UI) from local assets; the app is made with ``docs_url=None,
    redoc_url=None`` so FastAPI's CDN pages are not there."""
    app.mount(ASSETS, StaticFiles(directory=assets_dir()), name="docs-assets")
    title = app.title

    @app.get("/docs", include_in_schema=False)
    async def swagger() -> HTMLResponse:
        return _with_csp(get_swagger_ui_html(
            openapi_url=app.openapi_url or "/openapi.json", title=f"{title} · API",
            swagger_js_url=f"{ASSETS}/swagger-ui-bundle.js",
            swagger_css_url=f"{ASSETS}/swagger-ui.css",
            swagger_favicon_url=f"{ASSETS}/favicon.png",
            # No badge fetched from validator.swagger.io
            swagger_ui_parameters={"validatorUrl": None}))


# On every answer; also set by errors.on_crash, whose 500 leaves from outside the middleware.
SECURITY_HEADERS = {"X-Content-Type-Options": "nosniff", "Referrer-Policy": "no-referrer"}


class SecurityHeaders:
    """nosniff and no-referrer on every answer; the page's CSP on HTML that has none."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                for name, value in SECURITY_HEADERS.items():
                    headers.setdefault(name, value)
                if headers.get("content-type", "").startswith("text/html"):
                    headers.setdefault("Content-Security-Policy", PAGE_CSP)
                    headers.setdefault("X-Frame-Options", "DENY")
            await send(message)

        await self.app(scope, receive, send_with_headers)
