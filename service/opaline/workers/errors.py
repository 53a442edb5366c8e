"""Why a render did not come back: each carries its public answer in the HTTP service."""

from __future__ import annotations

import re

from opaline.errors import PublicError

# "mesh NAME: tangent_field='uv' but ...", "environment NAME: cannot read: ...": the file's
# field, and a field the message names first.
FILE_FIELD = re.compile(r"^(?:(mesh|environment) [^:]+: )?(?:(\w+)=)?")


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
    """The worker refused the job's input (a malformed or over-limit mesh file, an
    environment map it cannot read) (422); its ``fields`` name the request field at fault
    (they were empty: a tangent_field='uv' on a mesh without UVs named none)."""

    status, reason = 422, "invalid"

    def field_problems(self) -> list[dict[str, str]]:
        from opaline.model.params import RenderRequest

        text = str(self)
        found = FILE_FIELD.match(text)  # every part optional: it always matches
        assert found is not None
        name = found.group(2) if found.group(2) in RenderRequest.model_fields else found.group(1)
        return [{"field": name, "message": text}] if name else []


# The exception each non-failure reply kind of a worker becomes.
REFUSED: dict[str, type[Exception]] = {"cancelled": Cancelled, "invalid": InvalidInput}
