"""HTTP client for a running Opaline: ``GET`` each image's canonical URL, with bounded
retries.

A ``RenderRequest`` is asked at its canonical GET URL (``Prepared.url()``: what the
service names in Content-Location), so a shared cache in front of the service
(deploy/nginx) answers a repeated run without a render; a request only the service
can name (a mesh it stores, an environment file of its folder) and a plain dict are
POSTed as the body ``model_dump(exclude_none=True)``. The answer is the image bytes.
A 4xx carries ``{"detail": "message"}`` or ``{"detail": [...]}`` and is final. A 503
(queue full; ``Retry-After`` honoured) or a connection error is retried with
exponential backoff, at most ``retries`` times.
One ``RemoteRenderer`` may be shared by threads (httpx.Client is thread-safe).
"""

from __future__ import annotations

import random
import threading
import time
from typing import Any

import httpx

from opaline.errors import PublicError
from opaline.model.params import RenderRequest
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, prepare

RETRY_STATUSES = {503}
# No limits (the service applies its own) and no meshes: those only the service can name.
NAMING = Context(Limits(cost_budget=None), lambda request, preset: preset)


def canonical_path(request: RenderRequest) -> str | None:
    """``/v1/render?…&rev=…`` for ``request``, or None where only the service can name it."""
    if request.mesh is not None:
        return None
    try:
        return prepare(request, NAMING).url()
    except (PublicError, ValueError):  # an environment file of the service's folder ...
        return None


class RemoteError(RuntimeError):
    """The server refused or failed the request; ``status`` is None for transport errors."""

    def __init__(self, message: str, status: int | None = None) -> None:
        self.status = status
        super().__init__(message)


def detail_text(response: httpx.Response) -> str:
    """The server's error message(s) as one line."""
    try:
        detail = response.json().get("detail")
    except (ValueError, AttributeError):
        return response.text.strip()[:300] or response.reason_phrase
    if isinstance(detail, list):
        return "; ".join(_one_detail(d) for d in detail)
    return str(detail)


def _one_detail(detail: Any) -> str:
    if isinstance(detail, dict) and "msg" in detail:  # FastAPI's default validation shape
        loc = ".".join(str(p) for p in detail.get("loc", ()) if p != "body")
        return f"{loc}: {detail['msg']}" if loc else str(detail["msg"])
    return str(detail)


class RemoteRenderer:
    """Renders requests on an Opaline server."""

    def __init__(self, url: str, *, jobs: int = 4, timeout: float = 120.0, retries: int = 5,
                 backoff: float = 0.5, max_delay: float = 10.0,
                 client: httpx.Client | None = None) -> None:
        if retries < 0:
            raise ValueError(f"retries={retries} must be 0 or more")
        self.base = url.rstrip("/")
        self.url = self.base + "/v1/render"
        self.retries = retries
        self.backoff = backoff
        self.max_delay = max_delay
        limits = httpx.Limits(max_connections=jobs, max_keepalive_connections=jobs)
        self.client = client or httpx.Client(timeout=timeout, limits=limits)
        self.attempts = 0  # total HTTP attempts, retries included
        self._lock = threading.Lock()

    def __enter__(self) -> RemoteRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.client.close()

    def render(self, request: RenderRequest | dict[str, Any]) -> bytes:
        """The image bytes; raises RemoteError once the server refuses or retries run out."""
        path = canonical_path(request) if isinstance(request, RenderRequest) else None
        if isinstance(request, RenderRequest):
            body = request.model_dump(mode="json", exclude_none=True)
        else:
            body = request
        for attempt in range(self.retries + 1):
            last = attempt == self.retries
            with self._lock:
                self.attempts += 1
            try:
                response = (self.client.get(self.base + path) if path is not None
                            else self.client.post(self.url, json=body))
            except httpx.TransportError as exc:
                if last or isinstance(exc, httpx.UnsupportedProtocol):
                    raise RemoteError(f"{self.url}: {type(exc).__name__}: {exc} "
                                      f"(after {attempt + 1} attempts)") from None
                time.sleep(self.delay(attempt))
                continue
            if response.status_code in RETRY_STATUSES and not last:
                time.sleep(self.delay(attempt, response.headers.get("retry-after")))
                continue
            if response.is_success:
                return response.content
            suffix = f" (after {attempt + 1} attempts)" if attempt else ""
            raise RemoteError(f"HTTP {response.status_code}: {detail_text(response)}{suffix}",
                              response.status_code)
        raise AssertionError("unreachable")  # the last attempt returns or raises

    def delay(self, attempt: int, retry_after: str | None = None) -> float:
        """Seconds to wait: the server's Retry-After if given, else jittered exponential backoff."""
        if retry_after is not None:
            try:
                return min(max(float(retry_after), 0.0), self.max_delay)
            except ValueError:
                pass  # an HTTP date: fall back to our own backoff
        base: float = min(self.backoff * 2**attempt, self.max_delay)
        return base * random.uniform(0.5, 1.0)
