"""The worker pool: a bounded queue in front of supervised worker processes.

Admission (``admission``) refuses a job predicted to miss its deadline, alone
(422) or behind the queue (503); the reaper drops queued jobs whose deadline
passed; equal keys share one job; a job whose every waiter left is dropped
from the queue, or stopped between samples; each ``Slot`` supervises one process.
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import math
import threading
import time
import uuid
from collections import Counter, deque
from collections.abc import Awaitable, Callable, Sequence
from concurrent.futures import Future
from typing import Any

from opaline.workers.admission import CostModel, admit
from opaline.workers.child import Reply
from opaline.workers.errors import (
    REFUSED,
    Cancelled,
    DeadlineExceeded,
    RenderFailed,
    TooSlow,
    Unavailable,
)
from opaline.workers.job import Job, Store, awaited
from opaline.workers.slot import Slot
from opaline.workers.tasks import Task

log = logging.getLogger(__name__)
REAP_S = 0.1


class WorkerPool:
    """``workers`` processes behind a queue of ``queue_size`` jobs; ``startup``: the jobs
    that run first (warm-up, calibration), never expiring, before the pool is ready."""

    def __init__(self, factory: Callable[[], Any], workers: int = 1, queue_size: int = 32,
                 deadline_s: float = 10.0, render_timeout_s: float = 30.0,
                 max_renders: int = 1000, max_rss_bytes: int = 1 << 30,
                 lp_threads: int | None = None, cache: Store | None = None,
                 on_rendered: Callable[[str, float], None] | None = None,
                 startup: Sequence[Task] = (), start_timeout_s: float = 60.0) -> None:
        self.factory, self.size, self.queue_size = factory, workers, queue_size
        self.deadline_s, self.render_timeout_s = deadline_s, render_timeout_s
        self.max_renders, self.max_rss_bytes = max_renders, max_rss_bytes
        self.lp_threads, self.cache, self.on_rendered = lp_threads, cache, on_rendered
        self.startup, self.start_timeout_s = startup, start_timeout_s
        self.cost = CostModel()
        self.counters: Counter[str] = Counter()
        self.stopping = True
        self.warming: list[Future[bytes]] = []
        self.slots: list[Slot] = []
        self._queue: deque[Job] = deque()
        self._inflight: dict[str, Job] = {}
        self._ids = itertools.count(1)
        self._cond = threading.Condition()
        self._stop = threading.Event()

    def start(self, timeout: float | None = None) -> None:
        """Start the workers and wait until each has a context (or failed to make one)."""
        self.stopping = False
        self._stop.clear()
        self.slots = [Slot(self, i) for i in range(self.size)]
        for slot in self.slots:
            slot.thread.start()
        end = time.monotonic() + (timeout or self.start_timeout_s)
        for slot in self.slots:
            slot.opened.wait(max(0.0, end - time.monotonic()))
        threading.Thread(target=self._reap, name="opaline-reaper", daemon=True).start()
        if not self.ready:
            log.error("no render worker has a GL context: %s",
                      "; ".join(s.error or s.state for s in self.slots))
            return
        with self._cond:  # first in the queue, never expiring, counted in the backlog
            for task in self.startup:
                job = Job(next(self._ids), uuid.uuid4().hex, task, task.label, math.inf,
                          self.cost.predict(*task.units()))
                self._enqueue(job)
                self.warming.append(job.future)

    def stop(self, timeout: float = 10.0) -> None:
        """Refuse new jobs, fail the queued ones, and let each worker release its context."""
        with self._cond:
            self.stopping = True
            self._stop.set()
            queued, self._queue = list(self._queue), deque()
            self._cond.notify_all()
        for job in queued:
            self.fail(job, Unavailable("the service is shutting down"))
        end = time.monotonic() + timeout
        for slot in self.slots:
            slot.thread.join(max(0.0, end - time.monotonic()))
            if slot.thread.is_alive():
                log.warning("%s did not stop within %.0f s", slot.name, timeout)

    def wait_stop(self, seconds: float) -> None:
        self._stop.wait(seconds)

    def submit(self, key: str, task: Task, label: str = "") -> Job:
        """The job under ``key``: joined if in flight, else admitted and queued."""
        with self._cond:
            if self.stopping:
                raise Unavailable("the render workers are not running")
            found = self._inflight.get(key)
            if found is not None:
                found.waiters += 1
                return found
            job = Job(next(self._ids), key, task, label or task.label,
                      time.monotonic() + self.deadline_s, self.cost.predict_task(task))
            data = self.cache.get(key) if self.cache is not None else None
            if data is not None:  # rendered after the caller looked
                job.future.set_result(data)
                return job
            self._admit(job)
            self._enqueue(job)
            return job

    def _admit(self, job: Job) -> None:
        now = time.monotonic()
        running = [max(0.0, s.job.predicted - (now - s.job_started))
                   for s in self.slots if s.job is not None]
        # A worker being replaced counts: its job waits the second a new process takes.
        workers = sum(slot.state in ("ready", "busy", "starting") for slot in self.slots)
        refusal = admit(job.predicted, workers, running, [j.predicted for j in self._queue],
                        self.queue_size, self.deadline_s, job.label, job.task)
        if refusal is not None:
            self.counters["refused_too_slow" if isinstance(refusal, TooSlow)
                          else "refused_queue"] += 1
            raise refusal

    def _enqueue(self, job: Job) -> None:
        self._queue.append(job)
        self._inflight[job.key] = job
        self._cond.notify()

    async def render(self, key: str, task: Task, label: str = "", timeout: float | None = None,
                     gone: Callable[[], Awaitable[Any]] | None = None) -> bytes:
        """Submit and await; ``gone`` resolves when the client has left, which withdraws
        this waiter (and drops the job if it was the last)."""
        job = self.submit(key, task, label)
        result = awaited(job.future)
        watch = asyncio.ensure_future(gone()) if gone is not None else None
        try:
            waits = {result} | ({watch} if watch is not None else set())
            done, _ = await asyncio.wait(waits, timeout=timeout,
                                         return_when=asyncio.FIRST_COMPLETED)
            if result in done:
                return result.result()
            if watch is not None and watch in done:
                raise Cancelled("the client left")
            raise DeadlineExceeded(f"no image within {timeout:g} s")
        finally:
            if watch is not None:
                watch.cancel()
            self.leave(job)

    def leave(self, job: Job) -> None:
        """One waiter is gone; the last one takes a queued job out of the queue."""
        with self._cond:
            job.waiters -= 1
            if job.waiters > 0 or job.future.done():
                return
            if job in self._queue:
                self._queue.remove(job)
                self.counters["cancelled"] += 1
            else:
                return  # running: its slot sees waiters == 0 and stops it between samples
        self.fail(job, Cancelled("every client waiting for it left"))

    def take(self, slot: Slot) -> Job | None:
        with self._cond:
            if not self._queue:
                self._cond.wait(0.2)
            if not self._queue or self.stopping:
                return None
            return self._queue.popleft()

    def finish(self, job: Job, reply: Reply) -> None:
        job.seconds = reply.seconds
        if reply.kind == "ok" and reply.data is not None:
            if job.label == "calibration":
                self.cost.calibrate(reply.data)
            elif self.cache is not None:
                self.cache.put(job.key, reply.data)
            self.cost.warmed(job.task)
            self.cost.observe(job.task, job.predicted, reply.seconds)
            if self.on_rendered is not None:
                self.on_rendered(job.label, reply.seconds)
            self._settle(job, result=reply.data)
        elif reply.kind in REFUSED:  # cancelled, or the client's input was bad: no incident
            self.fail(job, REFUSED[reply.kind](reply.error))
        else:
            incident = uuid.uuid4().hex[:12]
            self.counters["render_failures"] += 1
            log.error("render %s (%s) failed, incident %s:\n%s", job.key, job.label, incident,
                      reply.error)
            self.fail(job, RenderFailed(incident))

    def fail(self, job: Job, exc: Exception) -> None:
        self._settle(job, error=exc)

    def _settle(self, job: Job, result: bytes = b"", error: Exception | None = None) -> None:
        with self._cond:
            if self._inflight.get(job.key) is job:
                del self._inflight[job.key]
        if job.future.done():
            return
        if error is not None:
            job.future.set_exception(error)
        else:
            job.future.set_result(result)

    def _reap(self) -> None:
        """Fail queued jobs whose deadline has passed, so they free their place at once."""
        while not self._stop.wait(REAP_S):
            now = time.monotonic()
            with self._cond:
                expired = [job for job in self._queue if job.deadline < now]
                for job in expired:
                    self._queue.remove(job)
            for job in expired:
                self.counters["expired"] += 1
                self.fail(job, DeadlineExceeded(f"queued longer than {self.deadline_s:g} s"))

    def depth(self) -> int:
        return len(self._queue)

    @property
    def ready(self) -> bool:
        """A worker can render now, and the start-up work (warm-up, calibration) is done."""
        return any(slot.ready for slot in self.slots) and all(f.done() for f in self.warming)

    @property
    def identity(self) -> str:
        """What draws the images, e.g. 'egl/llvmpipe (LLVM 15.0.6, 256 bits)/4.5 ...'."""
        for slot in self.slots:
            if slot.info:
                return "/".join(slot.info.get(k, "") for k in ("backend", "renderer", "version"))
        return ""

    def status(self) -> list[dict[str, Any]]:
        return [slot.status() for slot in self.slots]
