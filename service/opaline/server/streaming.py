"""Image answers that cost bounded memory however slowly the client reads.

A body handed to the server whole is copied into the connection's write buffer
as far as the socket does not take it: 24 clients that never read a 2048² .npy
held 24 copies of it (734 → 2181 MB). Sent in chunks, each ``send`` waits until
the previous chunk has drained below the transport's high-water mark, so a
stalled reader holds at most about one chunk plus that mark (the image itself
is the cache's, shared). The connection layer closes a reader stalled past the
write timeout (``opaline.server.connections``).
"""

from __future__ import annotations

from starlette.responses import Response
from starlette.types import Receive, Scope, Send

CHUNK_BYTES = 64 * 1024


class ChunkedResponse(Response):
    """A ``Response`` whose body goes out in ``CHUNK_BYTES`` slices (no copies made here)."""

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        await send({"type": "http.response.start", "status": self.status_code,
                    "headers": self.raw_headers})
        view = memoryview(self.body)
        size = len(view)
        if scope.get("method") == "HEAD" or size == 0:
            await send({"type": "http.response.body", "body": b""})
            return
        for start in range(0, size, CHUNK_BYTES):
            end = min(start + CHUNK_BYTES, size)
            await send({"type": "http.response.body", "body": bytes(view[start:end]),
                        "more_body": end < size})


def image_response(data: bytes, media_type: str, headers: dict[str, str]) -> Response:
    """``data`` as an answer: in one piece when small, in chunks when larger than one."""
    cls = ChunkedResponse if len(data) > CHUNK_BYTES else Response
    return cls(data, media_type=media_type, headers=headers)
