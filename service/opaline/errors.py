"""``PublicError``: a failure that carries its own public answer (status, reason, lines,
Retry-After), so the layer that raises it says how the HTTP service answers it.

Rank 0 so that any layer may define one; only ``opaline.server.errors`` turns them into
responses. Each subclass keeps its built-in base (``KeyError``, ``ValueError`` ...), which
the CLI, the batch runner and the Python API catch.
"""

from __future__ import annotations

import math
from typing import ClassVar


class PublicError(Exception):
    """A failure answered as ``{"error": reason, "detail": lines()}`` with ``status``."""

    status: ClassVar[int] = 500
    reason: ClassVar[str] = "error"
    # 429 and 503 answers: "; retry later" and a Retry-After header
    retry_later: ClassVar[bool] = False
    # Seconds the raiser suggests waiting; None: the service's retry_after_s
    retry_after_s: float | None = None

    def lines(self) -> list[str]:
        return [f"{self}; retry later" if self.retry_later else str(self)]

    def field_problems(self) -> list[dict[str, str]]:
        """The lines that are about one request field, with its name (a 422's ``fields``)."""
        return []

    def headers(self, retry_after_s: int) -> dict[str, str] | None:
        """Retry-After for a retry-later error: the suggested wait rounded up, never under
        the service's ``retry_after_s``."""
        if not self.retry_later:
            return None
        wait = retry_after_s if self.retry_after_s is None else self.retry_after_s
        return {"Retry-After": str(max(retry_after_s, math.ceil(wait)))}
