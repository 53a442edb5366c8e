"""Access control and rate limits, in front of every route (off by default).

Setting ``OPALINE_API_KEYS`` or ``OPALINE_SIGNING_KEY`` turns access control on
(docs/design.md, "Access control"): then /v1/… and /metrics answer only a
request with a valid API key (``X-API-Key`` or ``Authorization: Bearer``) or, for
a GET or HEAD image, a valid signed URL (``opaline.server.signing``); anything
else is 403. The probes, the page, its static files and the documentation stay
open: they show the API's shape, never an image or a figure. Keys are compared
in constant time and never written to an answer or a log line.

``OPALINE_RATE_LIMIT_PER_S`` limits each API key, or else each client address,
with a token bucket of ``OPALINE_RATE_BURST``; over it: 429 with Retry-After. The
probes, the page and its static files are never limited.
"""

from __future__ import annotations

import hashlib
import hmac
import math
import time
from collections import OrderedDict
from collections.abc import Callable

from starlette.types import ASGIApp, Receive, Scope, Send

from opaline.server import signing
from opaline.server.errors import problem
from opaline.settings import Settings, secrets

OPEN = ("/healthz", "/readyz", "/docs", "/openapi.json", "/static/", "/docs-assets/")
SIGNABLE = ("/v1/render", "/v1/mdf")
# Never rate-limited: the probes, and the page with its own files (one visit loads a
# dozen, which must not spend the budget its renders need).
UNLIMITED = ("/healthz", "/readyz", "/static/", "/docs-assets/")
MAX_BUCKETS = 65536  # distinct keys and addresses remembered; the least recent go first


class RateLimiter:
    """A token bucket per identity: ``rate`` per second, up to ``burst`` at once."""

    def __init__(self, rate: float, burst: int,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.rate, self.burst, self.clock = rate, burst, clock
        self.buckets: OrderedDict[str, tuple[float, float]] = OrderedDict()

    def wait_s(self, identity: str) -> float:
        """0 when a request may go now (and takes a token), else the seconds until it may."""
        now = self.clock()
        tokens, then = self.buckets.pop(identity, (float(self.burst), now))
        tokens = min(float(self.burst), tokens + (now - then) * self.rate)
        wait = 0.0 if tokens >= 1.0 else (1.0 - tokens) / self.rate
        self.buckets[identity] = (tokens - 1.0 if wait == 0.0 else tokens, now)
        if len(self.buckets) > MAX_BUCKETS:
            self.buckets.popitem(last=False)
        return wait


def presented_key(scope: Scope) -> bytes | None:
    headers: dict[bytes, bytes] = dict(scope["headers"])
    if b"x-api-key" in headers:
        return headers[b"x-api-key"]
    auth = headers.get(b"authorization", b"")
    return auth[7:].strip() if auth[:7].lower() == b"bearer " else None


def key_matches(keys: list[bytes], given: bytes) -> int | None:
    """Index of the key ``given`` equals (every key compared, each in constant time)."""
    found = None
    for i, key in enumerate(keys):
        if hmac.compare_digest(key, given):
            found = i
    return found


class Access:
    def __init__(self, app: ASGIApp, settings: Settings, on_reject: Callable[[str], None]
                 ) -> None:
        self.app, self.on_reject = app, on_reject
        self.keys = secrets(settings.api_keys)
        self.signing_keys = secrets(settings.signing_key)
        self.enabled = bool(self.keys or self.signing_keys)
        self.limiter = (RateLimiter(settings.rate_limit_per_s, settings.rate_burst)
                        if settings.rate_limit_per_s > 0 else None)

    def check(self, scope: Scope) -> tuple[str | None, str]:
        """(refusal or None, the identity to rate-limit)."""
        client = (scope.get("client") or ("unknown", 0))[0]
        path = scope["path"]
        if path == "/" or path.startswith(OPEN):
            return None, client
        given = presented_key(scope)
        if given is not None:
            index = key_matches(self.keys, given)
            if index is None:
                return ("this API key is not valid" if self.enabled else None), client
            # An identity that names the key without holding it (for the buckets only)
            return None, "key:" + hashlib.sha256(self.keys[index]).hexdigest()[:16]
        if not self.enabled:
            return None, client
        query = scope.get("query_string", b"").decode("latin-1")
        if (scope["method"] in ("GET", "HEAD") and path in SIGNABLE and self.signing_keys
                and signing.SIG + "=" in query):
            ok, why = signing.verify(self.signing_keys, path, query)
            if ok:
                scope["query_string"] = signing.strip(scope["query_string"])
            return (None if ok else why), client
        return "an API key (X-API-Key) or a signed URL is required", client

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        scope = dict(scope)
        refusal, identity = self.check(scope)
        if refusal is not None:
            self.on_reject("forbidden")
            await problem(403, "forbidden", refusal)(scope, receive, send)
            return
        path = scope["path"]
        if self.limiter is not None and path != "/" and not path.startswith(UNLIMITED):
            wait = self.limiter.wait_s(identity)
            if wait > 0:
                self.on_reject("rate_limited")
                retry = str(max(1, math.ceil(wait)))
                await problem(429, "rate_limited", f"over {self.limiter.rate:g} requests per "
                              f"second; retry in {retry} s",
                              headers={"Retry-After": retry})(scope, receive, send)
                return
        await self.app(scope, receive, send)
