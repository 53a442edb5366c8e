"""Where a batch renders: this machine's worker processes, or an Opaline server.

Every pool takes a planned ``batch.plan.Task`` and gives a future of
``(data, seconds, error)``: a failed render fails its item, not the batch.
Local renders go through the same supervised worker processes as the HTTP
service (``opaline.workers``): spawned, a GL context each, killed past the
time limit, and gone within a second when the batch itself is killed.
"""

from __future__ import annotations

import time
from concurrent.futures import Future, ThreadPoolExecutor
from functools import partial
from typing import TYPE_CHECKING

from opaline.workers.errors import RenderFailed
from opaline.workers.factory import RendererFactory
from opaline.workers.job import Job
from opaline.workers.pool import WorkerPool
from opaline.workers.tasks import ImageTask

if TYPE_CHECKING:
    from opaline.batch.client import RemoteRenderer
    from opaline.batch.plan import Task
    from opaline.model.params import RenderRequest

Outcome = tuple[bytes | None, float, str | None]
NO_DEADLINE_S = 1e9  # a batch waits for its own work; only the per-render limit applies
RENDER_LIMIT_S = 600.0


def start_pool(jobs: int, backend: str | None = None, server: str | None = None,
               retries: int = 5) -> GLProcesses | HttpThreads:
    """``jobs`` renders at once: on ``server`` if given, else in local worker processes."""
    if server:
        return HttpThreads(server, jobs, retries)
    return GLProcesses(jobs, backend)


class GLProcesses:
    """``jobs`` worker processes, a GL context each, the cores shared between their llvmpipes."""

    def __init__(self, jobs: int, backend: str | None) -> None:
        import os

        from opaline.settings import setting

        factory = RendererFactory(backend, environments_dir=setting("environments_dir"),
                                  environment_paths=True)
        self.pool = WorkerPool(factory, workers=jobs, queue_size=1 << 20,
                               deadline_s=NO_DEADLINE_S, render_timeout_s=RENDER_LIMIT_S,
                               lp_threads=max(1, (os.cpu_count() or 1) // jobs))
        self.pool.start()

    def submit(self, task: Task) -> Future[Outcome]:
        assert task.prepared is not None and task.key is not None  # only planned tasks run
        outcome: Future[Outcome] = Future()
        try:
            job = self.pool.submit(task.key, ImageTask(task.prepared))
        except Exception as exc:  # no worker has a context: the item fails with the reason
            outcome.set_result((None, 0.0, f"{type(exc).__name__}: {exc}"))
            return outcome
        job.future.add_done_callback(partial(_settle, job, outcome))
        return outcome

    def close(self) -> None:
        """The work in flight is done by now (the batch waited for it): release the workers."""
        self.pool.stop()

    def abort(self) -> None:
        """Stop now: drop the queued work and end the worker processes."""
        self.pool.stop(timeout=5.0)


def _settle(job: Job, outcome: Future[Outcome], done: Future[bytes]) -> None:
    exc = done.exception()
    if exc is None:
        outcome.set_result((done.result(), job.seconds, None))
    elif isinstance(exc, RenderFailed):
        outcome.set_result((None, job.seconds, f"{exc} (see the log above)"))
    else:
        outcome.set_result((None, job.seconds, f"{type(exc).__name__}: {exc}"))


class HttpThreads:
    """``jobs`` threads sending requests to an Opaline server, sharing one HTTP client."""

    def __init__(self, server: str, jobs: int, retries: int) -> None:
        from opaline.batch.client import RemoteRenderer

        self.remote = RemoteRenderer(server, jobs=jobs, retries=retries)
        self.executor = ThreadPoolExecutor(jobs, thread_name_prefix="opaline-http")

    def submit(self, task: Task) -> Future[Outcome]:
        assert task.item.request is not None  # planned: a pending task's item has a request
        return self.executor.submit(_render_remote, self.remote, task.item.request)

    def close(self) -> None:
        self.executor.shutdown(wait=True)
        self.remote.close()

    def abort(self) -> None:
        self.executor.shutdown(wait=False, cancel_futures=True)
        self.remote.close()


def _render_remote(remote: RemoteRenderer, request: RenderRequest) -> Outcome:
    from opaline.batch.client import RemoteError

    start = time.perf_counter()
    try:
        data = remote.render(request)
    except RemoteError as exc:
        return None, time.perf_counter() - start, str(exc)
    return data, time.perf_counter() - start, None
