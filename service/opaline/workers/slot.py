"""One supervised worker process and the parent thread that feeds it.

The thread starts the process, hands it one job at a time, and watches it:
a job that runs past the time limit gets the process killed (the watchdog),
a process that dies is replaced, and one that has rendered ``max_renders``
jobs or grown past ``max_rss_bytes`` is recycled; one with no heartbeat and no
CPU used (stopped, deadlocked) is replaced in seconds. The thread that starts a
process lives as long as it (parent-death signals follow the starting thread).
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import os
import threading
import time
from collections import Counter
from collections.abc import Callable
from typing import Any, Protocol

from opaline.workers import child
from opaline.workers.errors import DeadlineExceeded, InvalidInput, Unavailable
from opaline.workers.job import Job

log = logging.getLogger(__name__)
SPAWN = multiprocessing.get_context("spawn")
POLL_S = 0.05
RESPAWN_BACKOFF_S = (0.5, 1.0, 2.0, 5.0, 10.0)
HUNG_AFTER_S = 2.0  # 4 missed heartbeats and no CPU, in a job (checked after its time limit)


class Supervisor(Protocol):
    """What a slot needs of its pool (``opaline.workers.pool.WorkerPool``)."""

    factory: Callable[[], Any]
    lp_threads: int | None
    start_timeout_s: float
    render_timeout_s: float
    max_renders: int
    max_rss_bytes: int
    stopping: bool
    counters: Counter[str]

    def take(self, slot: Slot) -> Job | None: ...

    def finish(self, job: Job, reply: child.Reply) -> None: ...

    def fail(self, job: Job, exc: Exception) -> None: ...

    def wait_stop(self, seconds: float) -> None: ...


class Slot:
    def __init__(self, pool: Supervisor, index: int) -> None:
        self.pool = pool
        self.name = f"render-{index}"
        self.process: Any = None
        self.conn: Any = None
        self.cancel: Any = None
        self.heartbeat: Any = None  # child.beat's clock
        self._cpu = (-1, 0.0)  # (the worker's CPU ticks, when they last changed)
        self.state = "starting"  # starting, ready, busy, failed, stopped
        self.info: dict[str, str] = {}
        self.error = ""
        self.restarts = self.renders = self.total_renders = self.rss_bytes = 0
        self.lost_context = False  # replaced after a failure; the next context is a restart
        self.job: Job | None = None
        self.job_started = 0.0
        self.opened = threading.Event()
        self.thread = threading.Thread(target=self.run, name=f"opaline-{self.name}", daemon=True)
        self._stats: dict[str, int] = {}

    def status(self) -> dict[str, Any]:
        pid = self.process.pid if self.process is not None else None
        found = {"name": self.name, "state": self.state, "pid": pid,
                 "renders": self.total_renders,
                 "rss_bytes": child.rss_bytes(pid) if pid is not None else 0,
                 "restarts": self.restarts, **self.info}
        return found | ({"error": self.error} if self.error else {})

    @property
    def ready(self) -> bool:
        return self.state in ("ready", "busy")

    # The thread

    def run(self) -> None:
        failures = 0
        while not self.pool.stopping:
            if self.process is None and not self.spawn():
                self.opened.set()
                failures += 1
                self.pool.wait_stop(RESPAWN_BACKOFF_S[min(failures, len(RESPAWN_BACKOFF_S)) - 1])
                continue
            failures = 0
            self.opened.set()
            job = self.pool.take(self)
            if job is not None:
                self.serve(job)
            elif self.process is not None and not self.process.is_alive():
                log.error("%s: worker pid %d died while idle", self.name, self.process.pid)
                self.replace("died")
            elif self.hung():
                self.replace("hung")
        self.shutdown()
        self.state = "stopped"

    def spawn(self) -> bool:
        pool = self.pool
        parent, kid = SPAWN.Pipe()
        self.cancel = SPAWN.Value("b", 0, lock=False)
        self.heartbeat = SPAWN.Value("d", time.monotonic(), lock=False)
        process = SPAWN.Process(target=child.main, name=f"opaline-{self.name}", daemon=True,
                                args=(kid, pool.factory, os.getpid(), pool.lp_threads, self.cancel,
                                      self.heartbeat))
        process.start()
        kid.close()
        self.process, self.conn, self.renders = process, parent, 0
        # ("ready", the context's description) or ("failed", why)
        message: tuple[str, Any] = (parent.recv() if parent.poll(pool.start_timeout_s)
                                    else ("failed", "no answer"))
        if message[0] != "ready":
            self.error = f"no GL context: {message[1]}"
            log.error("%s: %s", self.name, self.error)
            self.kill()
            self.state = "failed"
            return False
        self.info, self.error, self.state = message[1], "", "ready"
        if self.lost_context:
            self.lost_context = False
            pool.counters["context_restarts"] += 1
        log.info("%s ready (pid %d): %s", self.name, process.pid, self.info)
        return True

    def serve(self, job: Job) -> None:
        self.cancel.value = 0
        self.job, self.job_started, self.state = job, time.monotonic(), "busy"
        try:
            self.conn.send((job.id, job.task))
            reply = self.await_reply(job)
        except (OSError, EOFError):  # the worker died before it read the job
            self.replace("died")
            self.pool.fail(job, Unavailable("the render worker died; try again"))
            reply = None
        finally:
            self.job, self.state = None, "ready" if self.process is not None else self.state
        if reply is None:
            return
        self.renders += 1
        self.total_renders += 1
        self.rss_bytes = reply.rss_bytes
        self.count_evictions(reply.stats)
        self.pool.finish(job, reply)
        if reply.kind == "crash":
            self.replace("crash")
        elif self.renders >= self.pool.max_renders or reply.rss_bytes > self.pool.max_rss_bytes:
            log.info("%s recycled after %d renders at %d MB", self.name, self.renders,
                     reply.rss_bytes >> 20)
            self.pool.counters["recycles"] += 1
            self.shutdown()

    def count_evictions(self, stats: dict[str, int]) -> None:
        """Add what the worker's caches evicted since its last reply (a new worker counts
        from 0 again)."""
        for name, value in stats.items():
            if name.endswith("_evictions"):
                delta = value - self._stats.get(name, 0)
                self.pool.counters[name] += delta if delta >= 0 else value
        self._stats = stats

    def await_reply(self, job: Job) -> child.Reply | None:
        # A task with its own, shorter limit (a mesh check) is refused as the input's fault.
        limit_s = min(self.pool.render_timeout_s, getattr(job.task, "time_limit_s", math.inf))
        limit = self.job_started + limit_s
        while not self.conn.poll(POLL_S):
            if self.pool.stopping:
                self.pool.fail(job, Unavailable("the service is shutting down"))
                self.kill()
                return None
            if job.waiters <= 0:
                self.cancel.value = 1  # the renderer stops at its next sample
            if not self.process.is_alive():
                self.replace("died")
                self.pool.fail(job, Unavailable("the render worker died; try again"))
                return None
            if time.monotonic() > limit:
                self.pool.counters["watchdog_kills"] += 1
                log.error("%s: job %s (%s) ran past %g s; killing pid %d", self.name, job.key,
                          job.label, limit_s, self.process.pid)
                self.replace("watchdog")
                self.pool.fail(job, InvalidInput(
                    f"{job.label} ran past this service's limit of {limit_s:g} s")
                    if limit_s < self.pool.render_timeout_s else DeadlineExceeded(
                    f"the render ran past the {self.pool.render_timeout_s:g} s limit"))
                return None
            if self.hung():
                self.replace("hung")
                self.pool.fail(job, Unavailable("the render worker stopped answering; try again"))
                return None
        try:
            reply: child.Reply = self.conn.recv()
            return reply
        except (EOFError, OSError):
            self.replace("died")
            self.pool.fail(job, Unavailable("the render worker died; try again"))
            return None

    def hung(self) -> bool:
        """No heartbeat nor CPU (a GIL-holding draw burns CPU) for ``HUNG_AFTER_S`` of a job."""
        if self.process is None or self.heartbeat is None:
            return False
        now, ticks = time.monotonic(), child.cpu_ticks(self.process.pid)
        if ticks != self._cpu[0]:
            self._cpu = (ticks, now)
        if now - max(self.heartbeat.value, self._cpu[1], self.job_started) <= HUNG_AFTER_S:
            return False
        log.error("%s: pid %d hung (no heartbeat, no CPU)", self.name, self.process.pid)
        return True

    def replace(self, reason: str) -> None:
        """Kill this worker; the thread's loop starts a new one."""
        self.restarts += 1
        self.lost_context = True
        self.pool.counters[f"restarts_{reason}"] += 1
        self.kill()
        self.state = "starting"

    def kill(self) -> None:
        process, self.process = self.process, None
        if process is not None and process.is_alive():
            process.kill()
        if process is not None:
            process.join(5)
        if self.conn is not None:
            self.conn.close()
            self.conn = None

    def shutdown(self) -> None:
        """Ask the worker to release its context and exit; kill it if it does not."""
        if self.process is None:
            return
        try:
            self.conn.send(None)
        except (OSError, EOFError):
            pass
        self.process.join(5)
        self.kill()

