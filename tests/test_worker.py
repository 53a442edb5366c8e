"""The render worker pool: bounded queue, deadlines, single flight, context recovery."""

from __future__ import annotations

import asyncio
import threading
import time

import moderngl
import pytest

from opaline.gl.shaders import ShaderError
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.server.cache import ImageCache
from opaline.server.metrics import Metrics
from opaline.server.worker import (
    DeadlineExceeded,
    Overloaded,
    RenderFailed,
    Unavailable,
    WorkerPool,
    image_task,
    mdf_task,
)

WAIT = 10.0  # no test should come near this; it only stops a broken pool from hanging


class FakeRenderer:
    """Stands in for a Renderer: records the thread it lives on and whether it was released."""

    made: list[FakeRenderer] = []

    def __init__(self) -> None:
        self.thread = threading.get_ident()
        self.released_on: int | None = None
        FakeRenderer.made.append(self)

    def release(self) -> None:
        self.released_on = threading.get_ident()


@pytest.fixture
def make_pool():
    pools: list[WorkerPool] = []
    FakeRenderer.made = []

    def make(**kwargs) -> WorkerPool:
        kwargs.setdefault("factory", FakeRenderer)
        pool = WorkerPool(**kwargs)
        pool.start(timeout=WAIT)
        pools.append(pool)
        return pool

    yield make
    for pool in pools:
        pool.stop(timeout=WAIT)


class Gate:
    """A task that blocks its worker until opened."""

    def __init__(self) -> None:
        self.entered = threading.Event()
        self.opened = threading.Event()

    def __call__(self, renderer) -> bytes:
        self.entered.set()
        assert self.opened.wait(WAIT)
        return b"gate"


def returning(data: bytes, calls: list | None = None):
    def task(renderer) -> bytes:
        if calls is not None:
            calls.append(renderer)
        return data

    return task


def test_job_runs_on_a_worker_with_its_renderer(make_pool):
    """A submitted task runs on the worker thread that made the renderer, and its bytes return."""
    pool = make_pool(workers=1)
    seen: list = []
    assert pool.submit("k", returning(b"png", seen)).result(WAIT) == b"png"
    assert seen[0] is FakeRenderer.made[0]
    assert seen[0].thread != threading.get_ident()


def test_full_queue_refuses_with_overloaded(make_pool):
    """With the worker busy and the queue full, the next distinct job raises Overloaded."""
    pool = make_pool(workers=1, queue_size=1)
    gate = Gate()
    busy = pool.submit("busy", gate)
    assert gate.entered.wait(WAIT)
    queued = pool.submit("queued", returning(b"q"))
    with pytest.raises(Overloaded):
        pool.submit("refused", returning(b"r"))
    assert pool.depth() == 1
    gate.opened.set()
    assert busy.result(WAIT) == b"gate" and queued.result(WAIT) == b"q"


def test_job_past_its_deadline_is_dropped_unrendered(make_pool):
    """A job that waited in the queue past its deadline fails with DeadlineExceeded, never runs."""
    pool = make_pool(workers=1, deadline_s=0.05)
    gate = Gate()
    pool.submit("busy", gate)
    assert gate.entered.wait(WAIT)
    ran: list = []
    late = pool.submit("late", returning(b"x", ran))
    time.sleep(0.15)
    gate.opened.set()
    with pytest.raises(DeadlineExceeded):
        late.result(WAIT)
    assert ran == []


def test_identical_jobs_render_once(make_pool):
    """Jobs with the same key while one is queued or running share one render."""
    pool = make_pool(workers=1)
    gate = Gate()
    pool.submit("busy", gate)
    assert gate.entered.wait(WAIT)
    calls: list = []
    futures = [pool.submit("same", returning(b"img", calls)) for _ in range(5)]
    assert len({id(f) for f in futures}) == 1
    gate.opened.set()
    assert [f.result(WAIT) for f in futures] == [b"img"] * 5
    assert len(calls) == 1


def test_finished_job_is_served_from_the_cache(make_pool):
    """Once a render is done and cached, the same key returns at once without a second render."""
    pool = make_pool(workers=1, cache=ImageCache(1000))
    calls: list = []
    assert pool.submit("k", returning(b"img", calls)).result(WAIT) == b"img"
    again = pool.submit("k", returning(b"other", calls))
    assert again.done() and again.result() == b"img"
    assert len(calls) == 1


def test_gl_failure_recreates_the_context(make_pool):
    """A GL error fails the job; the worker releases its context and makes a new one."""
    metrics = Metrics()
    pool = make_pool(workers=1, metrics=metrics)

    def lost(renderer) -> bytes:
        raise moderngl.Error("context lost")

    with pytest.raises(RenderFailed) as failed:
        pool.submit("bad", lost).result(WAIT)
    assert failed.value.incident
    first, second = FakeRenderer.made
    assert first.released_on == first.thread  # released on its own thread
    seen: list = []
    assert pool.submit("good", returning(b"ok", seen)).result(WAIT) == b"ok"
    assert seen == [second]
    assert pool.status()[0]["restarts"] == 1 and pool.ready
    assert metrics.context_restarts._value.get() == 1


def test_shader_error_keeps_the_context(make_pool):
    """A shader compile error fails the job but does not recreate the context."""
    pool = make_pool(workers=1)

    def broken(renderer) -> bytes:
        raise ShaderError("0:12(3): error: syntax error")

    with pytest.raises(RenderFailed):
        pool.submit("bad", broken).result(WAIT)
    assert len(FakeRenderer.made) == 1 and FakeRenderer.made[0].released_on is None


def test_failed_context_is_retried_and_reported(make_pool):
    """A worker without GL answers Unavailable, is not ready, and tries again on the next job."""
    attempts: list = []

    def flaky() -> FakeRenderer:
        attempts.append(1)
        if len(attempts) < 3:
            raise RuntimeError("no EGL device")
        return FakeRenderer()

    pool = make_pool(workers=1, factory=flaky)
    assert not pool.ready and "no EGL device" in pool.status()[0]["error"]
    with pytest.raises(Unavailable):
        pool.submit("a", returning(b"a")).result(WAIT)
    assert pool.submit("b", returning(b"b")).result(WAIT) == b"b"
    assert pool.ready


def test_cancelled_job_is_skipped_and_the_worker_keeps_serving(make_pool):
    """A queued job whose future was cancelled is not rendered, and its worker lives on."""
    pool = make_pool(workers=1)
    gate = Gate()
    pool.submit("busy", gate)
    assert gate.entered.wait(WAIT)
    ran: list = []
    assert pool.submit("cancelled", returning(b"x", ran)).cancel()
    gate.opened.set()
    assert pool.submit("next", returning(b"ok")).result(WAIT) == b"ok"
    assert ran == []


def test_context_that_cannot_describe_itself_fails_the_worker_at_once(make_pool):
    """A context lost before it is described: the worker is failed and releases it, no hang."""

    class Lost:
        def describe(self) -> dict[str, str]:
            raise RuntimeError("context lost")

    class Mute(FakeRenderer):
        gl = Lost()

    started = time.monotonic()
    pool = make_pool(workers=1, factory=Mute)
    assert time.monotonic() - started < WAIT / 2
    assert pool.status()[0]["state"] == "failed" and "context lost" in pool.status()[0]["error"]
    assert FakeRenderer.made[0].released_on == FakeRenderer.made[0].thread


def test_stop_fails_queued_jobs_and_releases_on_worker_threads(make_pool):
    """Stopping fails queued jobs with Unavailable; each context is released on its thread."""
    pool = make_pool(workers=2, queue_size=4)
    gates = [Gate(), Gate()]
    for i, gate in enumerate(gates):
        pool.submit(f"busy{i}", gate)
    for gate in gates:
        assert gate.entered.wait(WAIT)
    queued = pool.submit("queued", returning(b"q"))
    stopper = threading.Thread(target=pool.stop, kwargs={"timeout": WAIT})
    stopper.start()
    with pytest.raises(Unavailable):
        queued.result(2.0)  # at once: not after the busy workers finish
    for gate in gates:
        gate.opened.set()
    stopper.join(WAIT)
    assert all(r.released_on == r.thread for r in FakeRenderer.made)
    assert [w["state"] for w in pool.status()] == ["stopped", "stopped"]
    with pytest.raises(Unavailable):
        pool.submit("after", returning(b"x"))


def test_render_timeout_does_not_cancel_the_shared_job(make_pool):
    """A caller that stops waiting gets DeadlineExceeded; the shared render still finishes."""
    pool = make_pool(workers=1)
    gate = Gate()

    async def scenario() -> bytes:
        with pytest.raises(DeadlineExceeded):
            await pool.render("k", gate, timeout=0.05)
        gate.opened.set()
        return await pool.render("k", gate, timeout=WAIT)

    assert asyncio.run(scenario()) == b"gate"


def test_render_seconds_observed_by_label(make_pool):
    """Each render is timed in the histogram under its label."""
    metrics = Metrics()
    pool = make_pool(workers=1, metrics=metrics)
    pool.submit("k", returning(b"x"), label="sphere").result(WAIT)
    count = metrics.registry.get_sample_value("opaline_render_seconds_count", {"preset": "sphere"})
    assert count == 1


@pytest.mark.gl
def test_real_context_recovers_after_injected_failure(backend):
    """With real GL: a failing render costs the context, and the new context renders correctly."""
    from opaline.gl.renderer import Renderer

    made: list[Renderer] = []

    def factory() -> Renderer:
        made.append(Renderer(backend))
        return made[-1]

    pool = WorkerPool(factory, workers=1)
    pool.start(timeout=WAIT)
    try:
        job = resolve(RenderRequest(preset="sphere", width=32, height=32, quality="draft"))
        draw = image_task(job, get_preset("sphere"))
        before = pool.submit("a", draw).result(WAIT)

        def lost(renderer) -> bytes:
            renderer.render(job)
            raise moderngl.Error("injected: context lost")

        with pytest.raises(RenderFailed):
            pool.submit("b", lost).result(WAIT)
        after = pool.submit("c", draw).result(WAIT)
        plot = pool.submit("d", mdf_task(job.material, 32, "png", 0)).result(WAIT)
    finally:
        pool.stop(timeout=WAIT)
    assert len(made) == 2
    assert after == before and after.startswith(b"\x89PNG")
    assert plot.startswith(b"\x89PNG")
