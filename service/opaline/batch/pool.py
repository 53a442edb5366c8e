"""Where a batch renders: one GL thread, spawn-started processes, or HTTP threads.

Every pool takes a planned ``batch_plan.Task`` and gives a future of
``(data, seconds, error)``: a failed render fails its item, not the batch, and
no exception has to cross a process. Worker processes use the ``spawn`` start
method and make their GL context inside the worker: a context made before a
fork makes the children's contexts hang (DESIGN §8).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from concurrent.futures import Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from opaline.batch.client import RemoteRenderer
    from opaline.batch.plan import Task
    from opaline.model.params import RenderRequest
    from opaline.model.request import Job

Outcome = tuple[bytes | None, float, str | None]


def start_pool(jobs: int, backend: str | None = None, server: str | None = None,
               retries: int = 5) -> Pool:
    """``jobs`` renders at once: on ``server`` if given, else on this machine's GL."""
    if server:
        return HttpThreads(server, jobs, retries)
    if jobs == 1:
        return GLThread(backend)
    return GLProcesses(jobs, backend)


class Pool:
    """Renders tasks on this machine's GL (``_render_local``) unless a subclass sends them on."""

    executor: Executor
    backend: str | None = None

    def submit(self, task: Task) -> Future:
        return self.executor.submit(_render_local, task.job, self.backend)

    def close(self) -> None:
        """Finish the work in flight, then release the workers."""
        self.executor.shutdown(wait=True)

    def abort(self) -> None:
        """Stop now: drop the queued work."""
        self.executor.shutdown(wait=False, cancel_futures=True)


class GLThread(Pool):
    """One thread that owns the GL context, in this process."""

    def __init__(self, backend: str | None) -> None:
        self.backend = backend
        self.executor = ThreadPoolExecutor(1, thread_name_prefix="opaline-gl",
                                           initializer=_warm_up, initargs=(backend,))

    def close(self) -> None:
        from opaline.local import api as api_python

        self.executor.submit(api_python.close)  # the GL thread releases its own context
        super().close()


class GLProcesses(Pool):
    """``jobs`` spawned processes, a GL context each, the cores shared between their llvmpipes."""

    def __init__(self, jobs: int, backend: str | None) -> None:
        self.backend = backend
        lp_threads = max(1, (os.cpu_count() or 1) // jobs)
        self.executor = ProcessPoolExecutor(
            jobs, mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_process, initargs=(backend, lp_threads))

    def abort(self) -> None:
        """Stop now, the renders in flight too: end the worker processes."""
        # shutdown() forgets the processes (``_processes = None``): take them first.
        processes = list((getattr(self.executor, "_processes", None) or {}).values())
        super().abort()
        for process in processes:
            process.terminate()
        # Wait for them here, bounded, so abort() returns with no worker left running;
        # one stuck in a driver call that ignores SIGTERM gets SIGKILL.
        for process in processes:
            process.join(timeout=5)
            if process.is_alive():
                process.kill()
                process.join(timeout=5)


class HttpThreads(Pool):
    """``jobs`` threads sending requests to an Opaline server, sharing one HTTP client."""

    def __init__(self, server: str, jobs: int, retries: int) -> None:
        from opaline.batch.client import RemoteRenderer

        self.remote = RemoteRenderer(server, jobs=jobs, retries=retries)
        self.executor = ThreadPoolExecutor(jobs, thread_name_prefix="opaline-http")

    def submit(self, task: Task) -> Future:
        return self.executor.submit(_render_remote, self.remote, task.item.request)

    def close(self) -> None:
        super().close()
        self.remote.close()

    def abort(self) -> None:
        super().abort()
        self.remote.close()


# What runs in a worker.

def _render_local(job: Job, backend: str | None) -> Outcome:
    from opaline.local import api as api_python

    start = time.perf_counter()
    try:
        data = api_python.render_job(job, backend=backend)
    except Exception as exc:  # a shader or context failure fails this item, not the batch
        return None, time.perf_counter() - start, f"{type(exc).__name__}: {exc}"
    return data, time.perf_counter() - start, None


def _render_remote(remote: RemoteRenderer, request: RenderRequest) -> Outcome:
    from opaline.batch.client import RemoteError

    start = time.perf_counter()
    try:
        data = remote.render(request)
    except RemoteError as exc:
        return None, time.perf_counter() - start, str(exc)
    return data, time.perf_counter() - start, None


def _init_process(backend: str | None, lp_threads: int) -> None:
    """In a spawned worker: the parent handles Ctrl-C; share the cores between llvmpipes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ.setdefault("LP_NUM_THREADS", str(lp_threads))  # llvmpipe reads it at _warm_up
    _warm_up(backend)


def _warm_up(backend: str | None) -> None:
    """Make this worker's GL context now, so that item times are render times."""
    from opaline.local import api as api_python

    try:
        api_python.renderer(backend)
    except Exception:  # each item's render reports the failure with its message
        pass
