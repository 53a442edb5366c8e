"""Why a render did not come back: each maps to one public answer in the HTTP service."""

from __future__ import annotations


class Overloaded(Exception):
    """The queue is full, or the work ahead would make this job miss its deadline (503)."""

    def __init__(self, message: str, retry_after_s: float = 1.0) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


class TooSlow(ValueError):
    """The job alone is predicted to take longer than the deadline allows (422)."""


class DeadlineExceeded(Exception):
    """The job waited or ran past its limit and was given up (503)."""


class Unavailable(Exception):
    """No worker can render: no GL context, a lost worker, or the pool is stopping (503)."""


class Cancelled(Exception):
    """Every client waiting for the job left, so it was dropped."""


class RenderFailed(Exception):
    """The render raised; the details are in the server log under ``incident`` (500)."""

    def __init__(self, incident: str) -> None:
        super().__init__(f"render failed (incident {incident})")
        self.incident = incident


class InvalidInput(ValueError):
    """The worker refused the job's input (a malformed or over-limit mesh file) (422)."""


# The exception each non-failure reply kind of a worker becomes.
REFUSED: dict[str, type[Exception]] = {"cancelled": Cancelled, "invalid": InvalidInput}
