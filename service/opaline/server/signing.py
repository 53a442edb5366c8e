"""HMAC-signed GET URLs, so a page can embed ``<img src>`` without holding an API key.

The signature covers the path and the canonical query: every parameter but
``sig``, sorted by name (stably, so albedo's R, G, B keep their order), each name
and value percent-encoded as RFC 3986 leaves unreserved characters; ``exp``
(Unix seconds), when present, is part of it. ``sig`` is the unpadded base64url
of HMAC-SHA256 under the signing key. Who holds the key signs (a site's back
end, ``opaline sign``, or ``sign_url`` here); the service only verifies, in
constant time.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import time
from urllib.parse import parse_qsl, quote

SIG, EXP = "sig", "exp"


def canonical(path: str, params: list[tuple[str, str]]) -> bytes:
    """The signed text: path, '?', and the sorted, encoded parameters except ``sig``."""
    kept = sorted(((k, v) for k, v in params if k != SIG), key=lambda kv: kv[0])
    query = "&".join(f"{quote(k, safe='-_.~')}={quote(v, safe='-_.~')}" for k, v in kept)
    return f"{path}?{query}".encode()


def signature(key: bytes, path: str, params: list[tuple[str, str]]) -> str:
    digest = hmac.new(key, canonical(path, params), hashlib.sha256).digest()
    return base64.urlsafe_b64encode(digest).rstrip(b"=").decode()


def sign_url(key: bytes, path: str, params: list[tuple[str, str]],
             expires_at: int | None = None) -> str:
    """``path?query&sig=…`` (with ``exp=`` first when ``expires_at`` is given)."""
    params = [(k, v) for k, v in params if k not in (SIG, EXP)]
    if expires_at is not None:
        params.append((EXP, str(int(expires_at))))
    kept = sorted(params, key=lambda kv: kv[0])
    query = "&".join(f"{quote(k, safe='-_.~')}={quote(v, safe='-_.~')}" for k, v in kept)
    return f"{path}?{query}&{SIG}={signature(key, path, params)}"


def verify(keys: list[bytes], path: str, query_string: str,
           now: float | None = None) -> tuple[bool, str]:
    """Whether the query carries a valid, unexpired signature by one of ``keys``, and why not.

    Every key is tried (no early exit), each comparison in constant time."""
    params = parse_qsl(query_string, keep_blank_values=True)
    given = [v for k, v in params if k == SIG]
    if len(given) != 1:
        return False, "this URL is not signed (sig=)" if not given else "more than one sig="
    matched = False
    for key in keys:
        matched |= hmac.compare_digest(signature(key, path, params).encode(),
                                       given[0].encode("utf-8", "replace"))
    if not matched:
        return False, "the URL's signature does not match it"
    expiry = [v for k, v in params if k == EXP]
    if expiry:
        if len(expiry) > 1 or not expiry[0].isdigit():
            return False, "exp= must be one Unix time in seconds"
        if int(expiry[0]) < (time.time() if now is None else now):
            return False, "this signed URL has expired"
    return True, ""


def strip(query_string: bytes) -> bytes:
    """The query without ``sig`` and ``exp``, as the routes see it."""
    parts = [p for p in query_string.split(b"&")
             if p.split(b"=", 1)[0] not in (SIG.encode(), EXP.encode())]
    return b"&".join(parts)
