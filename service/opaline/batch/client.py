"""HTTP client for a running Opaline: ``POST {url}/v1/render``, with bounded retries.

The body is ``RenderRequest.model_dump(exclude_none=True)``; the answer is the
image bytes. A 4xx carries ``{"detail": "message"}`` or ``{"detail": [...]}``
and is final. A 503 (queue full; ``Retry-After`` honoured) or a connection
error is retried with exponential backoff, at most ``retries`` times.
One ``RemoteRenderer`` may be shared by threads (httpx.Client is thread-safe).
"""

from __future__ import annotations

import random
import threading
import time
from typing import Any

import httpx

from opaline.model.params import RenderRequest

RETRY_STATUSES = {503}


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
        self.url = url.rstrip("/") + "/v1/render"
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
        if isinstance(request, RenderRequest):
            body = request.model_dump(mode="json", exclude_none=True)
        else:
            body = request
        for attempt in range(self.retries + 1):
            last = attempt == self.retries
            with self._lock:
                self.attempts += 1
            try:
                response = self.client.post(self.url, json=body)
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
