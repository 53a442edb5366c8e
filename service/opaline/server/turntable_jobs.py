"""Turntable jobs as records of the state store, so that any replica answers for any job.

A job's record (``turntable:<id>``) holds its request, progress, state and the
failure it ended with; its result is the bytes ``turntable:<id>:result``. Both
expire ``OPALINE_TURNTABLE_KEEP_S`` after their last write. The replica running a
job owns it: each of its writes compares the version it last wrote (so a replica
that lost the job finds out and stops) and renews a lease. A job whose owner has
not renewed the lease for ``OPALINE_STATE_LEASE_S`` (it died, or lost the store)
is taken over by the next replica asked about it, which renders it again from its
request: an accepted job always ends with a result or a failure, never a 404.
"""

from __future__ import annotations

import asyncio
import logging
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TypeVar

from opaline.errors import PublicError
from opaline.server.statestore import Record, StateStore
from opaline.settings import Settings

LOG = logging.getLogger("opaline.turntables")
T = TypeVar("T")
CRASH = "internal error: the details are in the server log"  # as server.errors.on_crash says


class Lost(Exception):
    """This replica no longer owns the job (another took it over, or it was forgotten)."""


class StoredFailure(PublicError):
    """A failed job's failure as its record keeps it: answered as it was first raised."""

    def __init__(self, failure: dict[str, Any]) -> None:
        super().__init__(*failure["lines"])
        self.status, self.reason = failure["status"], failure["reason"]  # type: ignore[misc]
        self.retry_later = failure["retry_later"]  # type: ignore[misc]
        self.retry_after_s = failure["retry_after_s"]
        self._lines, self._fields = list(failure["lines"]), list(failure["fields"])

    def lines(self) -> list[str]:
        return list(self._lines)

    def field_problems(self) -> list[dict[str, str]]:
        return list(self._fields)


def failure_of(exc: Exception) -> dict[str, Any]:
    """What a job's record keeps of the exception it failed with."""
    if not isinstance(exc, PublicError):
        LOG.error("turntable failed", exc_info=exc)
        return {"status": 500, "reason": "error", "lines": [CRASH], "retry_later": False,
                "retry_after_s": None, "fields": []}
    return {"status": exc.status, "reason": exc.reason, "lines": exc.lines(),
            "retry_later": exc.retry_later, "retry_after_s": exc.retry_after_s,
            "fields": exc.field_problems()}


CANCELLED = {"status": 404, "reason": "cancelled", "retry_later": False, "retry_after_s": None,
             "lines": ["the turntable was cancelled (DELETE): POST it again to start it anew"],
             "fields": []}


def new_job(job_id: str, body: str, frames: int, fmt: str) -> dict[str, Any]:
    return {"id": job_id, "body": body, "frames": frames, "fmt": fmt, "done": 0,
            "state": "running", "error": None, "failure": None, "owner": "", "lease_until": 0.0}


@dataclass
class Job:
    """A job this replica runs: the record as it last wrote it."""

    id: str
    value: dict[str, Any]
    version: int
    lock: asyncio.Lock = field(default_factory=asyncio.Lock)


class Turntables:
    """The jobs in the store, and the ones this replica runs (``running``)."""

    def __init__(self, store: StateStore, settings: Settings) -> None:
        self.store = store
        self.owner = uuid.uuid4().hex  # this process: a restarted replica is a new owner
        self.keep_s = float(settings.turntable_keep_s)
        self.lease_s = settings.state_lease_s
        self.running: dict[str, tuple[Job, asyncio.Task[None]]] = {}

    async def call(self, step: Callable[..., T], *args: Any) -> T:
        """A store call; off the event loop when it goes over the network."""
        if self.store.shared:
            return await asyncio.to_thread(step, *args)
        return step(*args)

    async def read(self, job_id: str) -> Record | None:
        return await self.call(self.store.record, f"turntable:{job_id}")

    async def result(self, job_id: str) -> bytes | None:
        return await self.call(self.store.get, f"turntable:{job_id}:result")

    def orphaned(self, record: Record) -> bool:
        """Running, but owned by another process that has let its lease run out."""
        value = record.value
        return bool(value["state"] == "running" and value["owner"] != self.owner
                    and value["lease_until"] < time.time())

    async def claim(self, value: dict[str, Any], expect: int) -> Job | None:
        """Write ``value`` as this replica's job if the record is still at ``expect``."""
        value = {**value, "owner": self.owner, "lease_until": time.time() + self.lease_s}
        version = await self.call(self.store.put_record, f"turntable:{value['id']}", value,
                                  expect, self.keep_s)
        return None if version is None else Job(value["id"], value, version)

    async def update(self, job: Job, **changes: Any) -> None:
        """Write ``changes`` (and a renewed lease); Lost if the job is no longer ours."""
        async with job.lock:
            value = {**job.value, "lease_until": time.time() + self.lease_s, **changes}
            version = await self.call(self.store.put_record, f"turntable:{job.id}", value,
                                      job.version, self.keep_s)
            if version is None:
                raise Lost(job.id)
            job.value, job.version = value, version

    async def finish(self, job: Job, data: bytes) -> None:
        await self.call(self.store.put, f"turntable:{job.id}:result", data, self.keep_s)
        await self.update(job, state="done")

    async def fail(self, job: Job, exc: Exception) -> None:
        try:
            await self.update(job, state="failed", error=f"{type(exc).__name__}: {exc}",
                              failure=failure_of(exc))
        except Exception as lost:  # noqa: BLE001 (Lost, or the store down: the lease runs out)
            LOG.warning("turntable %s: its failure was not written (%s)", job.id, lost)

    async def cancel(self, job_id: str) -> Record | None:
        """Mark the job cancelled and drop its result; None if unknown. Its owner, here or
        on another replica, finds its record changed at its next write (Lost) and stops."""
        key = f"turntable:{job_id}"
        record = await self.read(job_id)
        while record is not None and record.value["state"] != "cancelled":
            value = {**record.value, "state": "cancelled", "error": "cancelled",
                     "failure": CANCELLED, "lease_until": 0.0}
            version = await self.call(self.store.put_record, key, value, record.version,
                                      self.keep_s)
            record = Record(version, value) if version is not None else await self.read(job_id)
        local = self.running.pop(job_id, None)
        if local is not None:  # out of the count now: a new one may start at once
            local[1].cancel()
        await self.call(self.store.delete, f"{key}:result")
        return record

    def forget(self, job_id: str, task: asyncio.Task[None]) -> None:
        """``task`` ended: no longer running here (unless a newer run of the id is)."""
        if self.running.get(job_id, (None, None))[1] is task:
            del self.running[job_id]

    async def stop(self) -> None:
        """At shutdown: stop this replica's jobs and give up their leases, so that another
        replica continues them at its next answer (not failed: nothing went wrong)."""
        for job, task in list(self.running.values()):
            task.cancel()
            try:
                await self.update(job, lease_until=0.0)
            except Exception as exc:  # noqa: BLE001 (the lease runs out by itself)
                LOG.warning("turntable %s: its lease was not given up (%s)", job.id, exc)

    async def heartbeat(self, job: Job, task: asyncio.Task[None]) -> None:
        """Renew the lease while frames render; stop ``task`` if the job is lost."""
        while not task.done():
            await asyncio.sleep(self.lease_s / 3)
            try:
                await self.update(job)
            except Lost:
                task.cancel()
            except PublicError:  # the store is down: try again; the lease may run out
                pass
