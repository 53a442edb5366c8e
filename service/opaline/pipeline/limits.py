"""What a request may cost where it runs: sizes and the cost budget.

The parameter ranges are the schema's; these are the deployment's own, tighter
ones (``OPALINE_MAX_WIDTH``, ``OPALINE_COST_BUDGET``), checked on the resolved
job so that every entry point refuses the same requests with the same words.
"""

from __future__ import annotations

from dataclasses import dataclass

from opaline.errors import PublicError
from opaline.model.request import Job, check_cost
from opaline.output.formats import HAS_ALPHA


class LimitError(PublicError, ValueError):
    """A request within the parameter ranges but over this service's configured limits."""

    status, reason = 422, "limit"

    def __init__(self, problems: list[str], fields: list[str | None] | None = None) -> None:
        super().__init__("; ".join(problems))
        self.problems = problems
        self.fields = fields or [None] * len(problems)  # the field each problem is about

    def lines(self) -> list[str]:
        return self.problems

    def field_problems(self) -> list[dict[str, str]]:
        return [{"field": name, "message": line}
                for name, line in zip(self.fields, self.problems, strict=True) if name is not None]


@dataclass(frozen=True)
class Limits:
    # None: no budget here (a batch that renders on a server leaves the check to it).
    cost_budget: int | None
    max_width: int | None = None
    max_height: int | None = None


def over_limit(name: str, value: int, limit: int) -> str:
    return f"{name}={value} is out of range: allowed [16 … {limit}] on this service"


def check_limits(job: Job, limits: Limits) -> None:
    """Refuse what the output cannot hold, then what is too large, then what costs too much."""
    if job.transparent and job.format not in HAS_ALPHA:
        raise LimitError([f"format={job.format} has no alpha channel: transparent=true needs "
                          "png, png16, webp, webp-lossless or avif"], ["format"])
    over = [(name, value, limit) for name, value, limit in (("width", job.width, limits.max_width),
                                                           ("height", job.height, limits.max_height))
            if limit is not None and value > limit]
    if over:
        raise LimitError([over_limit(*args) for args in over], [name for name, _, _ in over])
    if limits.cost_budget is not None:
        check_cost(job, limits.cost_budget)
