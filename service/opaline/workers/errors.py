"""Why a render did not come back: each carries its public answer in the HTTP service."""

from __future__ import annotations

from opaline.errors import PublicError


class Overloaded(PublicError):
    """The queue is full, or the work ahead would make this job miss its deadline (503)."""

    status, reason, retry_later = 503, "queue_full", True

    retry_after_s: float

    def __init__(self, message: str, retry_after_s: float = 1.0) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


class TooSlow(PublicError, ValueError):
    """The job alone is predicted to take longer than the deadline allows (422);
    ``fields``: the request's fields that its advice names."""

    status, reason = 422, "too_slow"

    def __init__(self, message: str, fields: list[str] | None = None) -> None:
        super().__init__(message)
        self.fields = fields or []

    def field_problems(self) -> list[dict[str, str]]:
        return [{"field": name, "message": str(self)} for name in self.fields]


class DeadlineExceeded(PublicError):
    """The job waited or ran past its limit and was given up (503)."""

    status, reason, retry_later = 503, "deadline", True


class Unavailable(PublicError):
    """No worker can render: no GL context, a lost worker, or the pool is stopping (503)."""

    status, reason, retry_later = 503, "unavailable", True


class Cancelled(PublicError):
    """Every client waiting for the job left, so it was dropped (503, to no one)."""

    status, reason, retry_later = 503, "cancelled", True


class RenderFailed(PublicError):
    """The render raised; the details are in the server log under ``incident`` (500)."""

    status, reason = 500, "render_failed"

    def __init__(self, incident: str) -> None:
        super().__init__(f"render failed (incident {incident})")
        self.incident = incident

    def lines(self) -> list[str]:
        return [f"{self}: the details are in the server log"]


class InvalidInput(PublicError, ValueError):
    """The worker refused the job's input (a malformed or over-limit mesh file) (422)."""

    status, reason = 422, "invalid"


# The exception each non-failure reply kind of a worker becomes.
REFUSED: dict[str, type[Exception]] = {"cancelled": Cancelled, "invalid": InvalidInput}
