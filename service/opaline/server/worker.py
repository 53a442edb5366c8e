"""Render workers: threads that each own one GL context, fed by a bounded queue.

A GL context is current on one thread (DESIGN §5), so each worker thread
makes its own ``Renderer``, uses it for every job it takes and releases it
before the thread ends; no other thread touches it. Around the threads:

- a bounded queue: a job that finds it full is refused (``Overloaded``, 503);
- a deadline: a job still queued after ``deadline_s`` is dropped unrendered;
- single flight: a job whose key is already queued or rendering joins it;
- recovery: a render that raises (other than a shader compile error) costs
  the worker its context, which it releases and makes anew.

moderngl holds the GIL through every GL call, so worker threads do not
overlap their draws; they overlap only the GIL-free parts (PNG compression,
waiting on the queue). See bench/results/http_load.md for what that means
for the worker count.
"""

from __future__ import annotations

import asyncio
import logging
import queue
import threading
import time
import uuid
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any

from opaline.gl.shaders import ShaderError
from opaline.model.params import Material
from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.output.encode import encode_frame, encode_mdf
from opaline.server.cache import ImageCache
from opaline.server.metrics import Metrics

log = logging.getLogger(__name__)

Task = Callable[[Any], bytes]  # called on a worker thread with that worker's Renderer
POLL_S = 0.2  # how often an idle worker looks at the stop flag


class Overloaded(Exception):
    """The queue is full; the client should retry later."""


class DeadlineExceeded(Exception):
    """The job waited (or ran) past its deadline and was given up."""


class Unavailable(Exception):
    """No worker can render: no GL context, or the pool is stopping."""


class RenderFailed(Exception):
    """The render raised; the details are in the server log under ``incident``."""

    def __init__(self, incident: str) -> None:
        super().__init__(f"render failed (incident {incident})")
        self.incident = incident


def image_task(job: Job, preset: Preset) -> Task:
    """Render a resolved job and encode it in the job's format."""

    def run(renderer: Any) -> bytes:
        frame = renderer.render(job, preset)
        return encode_frame(frame, job.format, alpha=job.transparent)

    return run


def mdf_task(material: Material, size: int, fmt: str, wavelengths: int) -> Task:
    """Plot the MDF (as ``LocalRenderer.mdf_bytes``): normalised sRGB PNG or linear npy."""

    def run(renderer: Any) -> bytes:
        return encode_mdf(renderer.mdf_plot(material, size, wavelengths), fmt)

    return run


@dataclass(eq=False)
class _Queued:
    key: str
    task: Task
    label: str
    deadline: float
    future: Future = field(default_factory=Future)


@dataclass(eq=False)
class _Worker:
    name: str
    renderer: Any = None
    state: str = "starting"  # starting, ready, failed, stopped
    info: dict[str, str] = field(default_factory=dict)
    error: str = ""
    restarts: int = 0
    opened: threading.Event = field(default_factory=threading.Event)

    def status(self) -> dict[str, Any]:
        found = {"name": self.name, "state": self.state, "restarts": self.restarts, **self.info}
        return found | ({"error": self.error} if self.error else {})


class WorkerPool:
    """``workers`` render threads behind a queue of ``queue_size`` jobs."""

    def __init__(self, factory: Callable[[], Any], workers: int = 1, queue_size: int = 32,
                 deadline_s: float = 10.0, cache: ImageCache | None = None,
                 metrics: Metrics | None = None, warmup: Task | None = None) -> None:
        self.factory = factory
        self.size = workers
        self.deadline_s = deadline_s
        self.cache = cache
        self.metrics = metrics
        self.warmup = warmup
        self._queue: queue.Queue[_Queued | None] = queue.Queue(maxsize=queue_size)
        self._inflight: dict[str, Future] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._stop.set()
        self._workers: list[_Worker] = []
        self._threads: list[threading.Thread] = []

    # Lifecycle (called from the app's lifespan)

    def start(self, timeout: float = 60.0) -> None:
        """Start the threads and wait until each has a context (or failed to make one)."""
        self._stop.clear()
        self._workers = [_Worker(f"render-{i}") for i in range(self.size)]
        self._threads = [threading.Thread(target=self._run, args=(w,), name=f"opaline-{w.name}",
                                          daemon=True) for w in self._workers]
        for thread in self._threads:
            thread.start()
        end = time.monotonic() + timeout
        for worker in self._workers:
            worker.opened.wait(max(0.0, end - time.monotonic()))
        if not self.ready:
            log.error("no render worker has a GL context: %s",
                      "; ".join(w.error or w.state for w in self._workers))

    def stop(self, timeout: float = 10.0) -> None:
        """Refuse new jobs, fail the queued ones, and let each worker release its context."""
        with self._lock:
            self._stop.set()
        self._drain()
        for _ in self._threads:  # wake idle workers now rather than at their next poll
            try:
                self._queue.put_nowait(None)
            except queue.Full:
                break
        end = time.monotonic() + timeout
        for thread in self._threads:
            thread.join(max(0.0, end - time.monotonic()))
            if thread.is_alive():
                log.warning("%s did not stop within %.0f s", thread.name, timeout)
        self._drain()

    def _drain(self) -> None:
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is not None:
                self._fail(item, Unavailable("the service is shutting down"))

    # Submitting (called from the event loop)

    def submit(self, key: str, task: Task, label: str = "") -> Future:
        """A future for the bytes under ``key``: joined if in flight, else queued."""
        with self._lock:
            if self._stop.is_set():
                raise Unavailable("the render workers are not running")
            found = self._inflight.get(key)
            if found is not None:
                return found
            # A render that finished after the caller's cache lookup is in the cache by now:
            # workers store before they leave ``_inflight``.
            data = self.cache.get(key) if self.cache is not None else None
            item = _Queued(key, task, label, time.monotonic() + self.deadline_s)
            if data is not None:
                item.future.set_result(data)
                return item.future
            try:
                self._queue.put_nowait(item)
            except queue.Full:
                raise Overloaded(f"{self._queue.maxsize} jobs are already waiting") from None
            self._inflight[key] = item.future
            return item.future

    async def render(self, key: str, task: Task, label: str = "",
                     timeout: float | None = None) -> bytes:
        """Submit and await; waiting callers never cancel the shared render."""
        future = asyncio.wrap_future(self.submit(key, task, label))
        try:
            return await asyncio.wait_for(asyncio.shield(future), timeout)
        except TimeoutError:
            raise DeadlineExceeded(f"no image within {timeout:g} s") from None

    # State (read from any thread; written only by the workers)

    def depth(self) -> int:
        return self._queue.qsize()

    @property
    def ready(self) -> bool:
        return any(w.state == "ready" for w in self._workers)

    @property
    def identity(self) -> str:
        """What draws the images, e.g. 'egl/llvmpipe (LLVM 15.0.6, 256 bits)/4.5 ...'."""
        for worker in self._workers:
            if worker.info:
                return "/".join(worker.info.get(k, "") for k in ("backend", "renderer", "version"))
        return ""

    def status(self) -> list[dict[str, Any]]:
        return [w.status() for w in self._workers]

    # The worker thread

    def _run(self, worker: _Worker) -> None:
        self._open(worker)
        worker.opened.set()
        while not self._stop.is_set():
            try:
                item = self._queue.get(timeout=POLL_S)
            except queue.Empty:
                continue
            if item is not None:
                self._serve(worker, item)
        self._close(worker)
        worker.state = "stopped"

    def _open(self, worker: _Worker) -> None:
        # Nothing may escape: an exception here would end the thread without setting
        # ``opened`` (start() then waits its whole timeout) or releasing the context.
        try:
            worker.renderer = self.factory()
            gl = getattr(worker.renderer, "gl", None)
            worker.info = gl.describe() if gl is not None else {}
        except Exception as exc:  # any failure leaves the worker without GL
            log.exception("%s: no GL context", worker.name)
            self._close(worker)
            worker.state, worker.error = "failed", f"{type(exc).__name__}: {exc}"
            return
        try:
            if self.warmup is not None:
                self.warmup(worker.renderer)
        except Exception as exc:
            log.exception("%s: warm-up render failed", worker.name)
            self._close(worker)
            worker.state, worker.error = "failed", f"warm-up failed: {exc}"
            return
        worker.state, worker.error = "ready", ""
        log.info("%s ready: %s", worker.name, worker.info)

    def _close(self, worker: _Worker) -> None:
        renderer, worker.renderer = worker.renderer, None
        if renderer is None:
            return
        try:
            renderer.release()
        except Exception:  # a lost context may not release cleanly
            log.exception("%s: releasing the GL context failed", worker.name)

    def _serve(self, worker: _Worker, item: _Queued) -> None:
        # A future someone cancelled is not rendered; one marked running can no longer be
        # cancelled, so setting its result below cannot raise and end the thread.
        if not item.future.set_running_or_notify_cancel():
            self._forget(item)
            return
        if self._stop.is_set():
            self._fail(item, Unavailable("the service is shutting down"))
            return
        if time.monotonic() > item.deadline:
            self._fail(item, DeadlineExceeded(f"queued longer than {self.deadline_s:g} s"))
            return
        if worker.renderer is None:
            self._open(worker)
            if worker.renderer is None:
                self._fail(item, Unavailable("the render worker has no GL context "
                                             "(the server log says why)"))
                return
        start = time.perf_counter()
        try:
            data = item.task(worker.renderer)
        except ShaderError:
            self._failed_render(item, recreate=False)
        except Exception:  # GL errors, lost contexts, anything the draw raised
            self._failed_render(item, recreate=True)
            self._restart(worker)
        else:
            if self.metrics is not None:
                self.metrics.render_seconds.labels(item.label).observe(time.perf_counter() - start)
            self._succeed(item, data)

    def _failed_render(self, item: _Queued, recreate: bool) -> None:
        incident = uuid.uuid4().hex[:12]
        log.exception("render %s (%s) failed, incident %s%s", item.key, item.label, incident,
                      "; recreating the GL context" if recreate else "")
        if self.metrics is not None:
            self.metrics.render_failures.inc()
        self._fail(item, RenderFailed(incident))

    def _restart(self, worker: _Worker) -> None:
        worker.restarts += 1
        if self.metrics is not None:
            self.metrics.context_restarts.inc()
        self._close(worker)
        worker.state = "starting"
        self._open(worker)

    def _succeed(self, item: _Queued, data: bytes) -> None:
        if self.cache is not None:
            self.cache.put(item.key, data)
        self._forget(item)
        item.future.set_result(data)

    def _fail(self, item: _Queued, exc: Exception) -> None:
        self._forget(item)
        if not item.future.done():
            item.future.set_exception(exc)

    def _forget(self, item: _Queued) -> None:
        with self._lock:
            if self._inflight.get(item.key) is item.future:
                del self._inflight[item.key]
