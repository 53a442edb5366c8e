"""413 for a request body over the limit, before a route reads it."""

from __future__ import annotations

from typing import Any

from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from opaline.server.errors import problem


class BodyLimit:
    """413 for a body over ``limit`` bytes: by its Content-Length, or counted as it arrives."""

    def __init__(self, app: ASGIApp, limit: int, on_reject: Any,
                 paths: dict[str, int] | None = None) -> None:
        self.app, self.limit, self.on_reject = app, limit, on_reject
        self.paths = paths or {}  # routes whose body is a file, with their own limit

    def _refuse(self, limit: int, count: bool = True) -> str:
        """Count the rejection (unless the error handler will); the message to answer it with."""
        if count:
            self.on_reject()
        return f"request body over the {limit} byte limit"

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        limit = self.paths.get(scope.get("path", ""), self.limit)
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared.isdigit() and int(declared) > limit:
            await problem(413, "too_large", self._refuse(limit))(scope, receive, send)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > limit:
                # The route's body reader re-raises it; on_http_error answers and counts it
                raise HTTPException(413, self._refuse(limit, count=False))
            return message

        await self.app(scope, counted, send)
