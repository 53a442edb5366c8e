"""A job in the pool: what it runs, when it must be done, and who still waits for it."""

from __future__ import annotations

import asyncio
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Protocol

from opaline.workers.tasks import Task


class Store(Protocol):
    def get(self, key: str) -> bytes | None: ...

    def put(self, key: str, data: bytes) -> None: ...


@dataclass(eq=False)
class Job:
    id: int
    key: str
    task: Task
    label: str
    deadline: float
    predicted: float
    future: Future[bytes] = field(default_factory=Future)
    waiters: int = 1
    seconds: float = 0.0  # the worker's time for it, once done


def awaited(future: Future[bytes]) -> asyncio.Future[bytes]:
    """``future`` for asyncio, its outcome read even where no one awaits it any more (the
    client left): asyncio logged "Future exception was never retrieved" for each such job."""
    found = asyncio.ensure_future(asyncio.wrap_future(future))
    found.add_done_callback(lambda done: done.cancelled() or done.exception())
    return found
