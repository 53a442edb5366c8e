"""The worker pool: processes supervised, queue bounded, jobs admitted, cancelled and reaped."""

from __future__ import annotations

import asyncio
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from opaline.workers.errors import (
    Cancelled,
    DeadlineExceeded,
    InvalidInput,
    Overloaded,
    TooSlow,
    Unavailable,
)
from opaline.workers.pool import WorkerPool
from worker_helpers import CrashTask, EchoTask, GateTask, SlowCheckTask, SpinTask, null_renderer

WAIT = 20.0
TESTS = Path(__file__).resolve().parents[1]  # tests/, where worker_helpers.py is


@pytest.fixture
def make_pool():
    pools: list[WorkerPool] = []

    def make(**kwargs) -> WorkerPool:
        kwargs.setdefault("factory", null_renderer)
        pool = WorkerPool(**kwargs)
        pool.start()
        pools.append(pool)
        return pool

    yield make
    for pool in pools:
        pool.stop()


def running(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] not in ("Z", "X")


def wait_until(condition, timeout: float = WAIT) -> None:
    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "condition not reached in time"
        time.sleep(0.02)


def test_each_worker_is_its_own_process(make_pool):
    """Workers are processes other than this one, each ready, each answering jobs."""
    pool = make_pool(workers=2)
    pids = [w["pid"] for w in pool.status()]
    assert len(set(pids)) == 2 and os.getpid() not in pids and all(map(running, pids))
    assert pool.submit("a", EchoTask(b"a")).future.result(WAIT) == b"a"


def test_a_queued_job_every_client_left_is_dropped(make_pool, tmp_path):
    """The last waiter leaving takes a queued job out of the queue; it is never run."""
    pool = make_pool(workers=1)
    gate = GateTask(str(tmp_path))
    pool.submit("gate", gate)
    gate.wait_entered()
    job = pool.submit("queued", EchoTask())
    assert pool.depth() == 1
    pool.leave(job)
    assert pool.depth() == 0 and pool.counters["cancelled"] == 1
    with pytest.raises(Cancelled):
        job.future.result(1)
    gate.open()


def test_a_running_job_every_client_left_is_stopped(make_pool, tmp_path):
    """A render whose clients all left is stopped between samples, not run to the end."""
    pool = make_pool(workers=1)
    gate = GateTask(str(tmp_path))  # would run for 20 s unless stopped

    async def ask_then_leave() -> None:
        left = asyncio.get_running_loop().create_future()
        asyncio.get_running_loop().call_later(0.3, left.set_result, None)
        await pool.render("gate", gate, timeout=WAIT, gone=lambda: left)

    start = time.monotonic()
    with pytest.raises(Cancelled):
        asyncio.run(ask_then_leave())
    wait_until(lambda: pool.status()[0]["state"] == "ready", timeout=5)
    assert time.monotonic() - start < 5
    assert pool.submit("next", EchoTask(b"next")).future.result(WAIT) == b"next"


def test_queued_jobs_leave_the_queue_when_their_deadline_passes(make_pool, tmp_path):
    """The reaper fails a queued job at its deadline, freeing its slot while the worker is busy."""
    pool = make_pool(workers=1, deadline_s=0.3, queue_size=1)
    gate = GateTask(str(tmp_path))
    pool.submit("gate", gate)
    gate.wait_entered()
    job = pool.submit("late", EchoTask())
    with pytest.raises(DeadlineExceeded):
        job.future.result(2)
    assert pool.depth() == 0 and pool.counters["expired"] == 1
    pool.submit("room again", EchoTask())  # the freed slot takes a new job
    gate.open()


def test_a_full_queue_refuses_with_a_retry_hint(make_pool, tmp_path):
    pool = make_pool(workers=1, queue_size=1)
    gate = GateTask(str(tmp_path))
    pool.submit("gate", gate)
    gate.wait_entered()
    pool.submit("one", EchoTask())
    with pytest.raises(Overloaded) as refused:
        pool.submit("two", EchoTask())
    assert refused.value.retry_after_s >= 1
    gate.open()


def test_a_job_predicted_past_the_deadline_is_refused_at_once(make_pool):
    """Admission: predicted seconds over the deadline → TooSlow, nothing queued."""
    from opaline.model.params import Material
    from opaline.workers.tasks import MdfTask

    pool = make_pool(workers=1, deadline_s=1.0)
    huge = MdfTask(Material(), 2048, "png", 128)
    assert pool.cost.predict(*huge.units()) > 1.0
    start = time.perf_counter()
    with pytest.raises(TooSlow, match="predicted"):
        pool.submit("huge", huge)
    assert time.perf_counter() - start < 0.05 and pool.depth() == 0
    assert pool.counters["refused_too_slow"] == 1


def test_a_crashed_worker_is_replaced_and_its_job_answered(make_pool):
    pool = make_pool(workers=1)
    before = pool.status()[0]["pid"]
    with pytest.raises(Unavailable, match="died"):
        pool.submit("crash", CrashTask()).future.result(WAIT)
    wait_until(lambda: pool.status()[0]["state"] == "ready")
    assert pool.status()[0]["pid"] != before and pool.status()[0]["restarts"] == 1
    assert pool.counters["context_restarts"] == 1
    assert pool.submit("after", EchoTask(b"ok")).future.result(WAIT) == b"ok"


def test_a_hung_worker_is_killed_past_the_time_limit(make_pool):
    """A stopped worker (SIGSTOP: as hung as a driver can be) is killed by the watchdog."""
    pool = make_pool(workers=1, render_timeout_s=1.0)
    pid = pool.status()[0]["pid"]
    os.kill(pid, signal.SIGSTOP)
    start = time.monotonic()
    with pytest.raises(DeadlineExceeded, match="limit"):
        pool.submit("hang", EchoTask()).future.result(WAIT)
    assert time.monotonic() - start < 1.0 + 1.0
    assert pool.counters["watchdog_kills"] == 1 and not running(pid)
    assert pool.submit("after", EchoTask(b"ok")).future.result(WAIT) == b"ok"


def test_a_task_past_its_own_time_limit_is_refused_as_invalid(make_pool):
    """A mesh check has a limit of its own, far under the render watchdog's: past it the
    worker is killed and replaced, and the file is refused (422) naming the limit."""
    pool = make_pool(workers=1, render_timeout_s=30.0)
    pid = pool.status()[0]["pid"]
    start = time.monotonic()
    with pytest.raises(InvalidInput, match="mesh-check ran past this service's limit of 0.5 s"):
        pool.submit("slow", SlowCheckTask()).future.result(WAIT)
    assert time.monotonic() - start < 0.5 + 1.0
    assert pool.counters["watchdog_kills"] == 1 and not running(pid)
    assert pool.submit("after", EchoTask(b"ok")).future.result(WAIT) == b"ok"


def test_a_mesh_check_costs_admission_its_predicted_time():
    """Priced by the file's size, never free, never past its own limit."""
    from opaline.workers.admission import CHECK_TIME_LIMIT_S, CostModel

    model = CostModel()
    small, large = model.predict("mesh-check", 1e4, 0), model.predict("mesh-check", 64e6, 0)
    assert 1.0 < small < large == CHECK_TIME_LIMIT_S


def test_a_stopped_worker_is_replaced_within_seconds(make_pool):
    """Heartbeats: a worker stopped while idle (SIGSTOP) is replaced within 3 s, with no
    job to time out; a job handed to it meanwhile is answered 503 as soon as it is found."""
    pool = make_pool(workers=1, render_timeout_s=30.0)
    pid = pool.status()[0]["pid"]
    os.kill(pid, signal.SIGSTOP)
    start = time.monotonic()
    with pytest.raises(Unavailable, match="stopped answering"):
        pool.submit("stuck", EchoTask()).future.result(WAIT)
    assert time.monotonic() - start < 3.0 and not running(pid)
    assert pool.counters["restarts_hung"] == 1 and pool.counters["watchdog_kills"] == 0
    assert pool.submit("after", EchoTask(b"ok")).future.result(WAIT) == b"ok"
    idle = pool.status()[0]["pid"]
    os.kill(idle, signal.SIGSTOP)
    wait_until(lambda: pool.status()[0]["pid"] not in (idle, None), timeout=3.0 + 1.0)
    assert not running(idle) and pool.counters["restarts_hung"] == 2


def test_a_busy_worker_that_uses_cpu_is_not_hung(make_pool):
    """A render holding the GIL (no heartbeat) while it burns CPU is left to finish."""
    pool = make_pool(workers=1, render_timeout_s=30.0)
    assert pool.submit("spin", SpinTask(3.0)).future.result(WAIT) == b"spun"
    assert pool.counters["restarts_hung"] == 0


def test_a_worker_killed_while_idle_is_replaced(make_pool):
    pool = make_pool(workers=1)
    pid = pool.status()[0]["pid"]
    os.kill(pid, signal.SIGKILL)
    wait_until(lambda: pool.status()[0]["pid"] not in (pid, None)
               and pool.status()[0]["state"] == "ready")
    assert pool.submit("after", EchoTask(b"ok")).future.result(WAIT) == b"ok"


def test_workers_are_recycled_after_max_renders(make_pool):
    pool = make_pool(workers=1, max_renders=2)
    first = pool.status()[0]["pid"]
    for i in range(3):
        pool.submit(f"job{i}", EchoTask()).future.result(WAIT)
    wait_until(lambda: pool.status()[0]["pid"] not in (first, None))
    assert pool.counters["recycles"] >= 1
    assert pool.counters["context_restarts"] == 0  # a recycle follows no failure


def test_workers_are_recycled_past_their_memory_limit(make_pool):
    pool = make_pool(workers=1, max_rss_bytes=1)  # every worker is over 1 byte
    first = pool.status()[0]["pid"]
    pool.submit("one", EchoTask()).future.result(WAIT)
    wait_until(lambda: pool.status()[0]["pid"] not in (first, None))
    assert pool.counters["recycles"] == 1


def test_workers_die_with_their_parent(tmp_path):
    """SIGKILL of the process that owns the pool leaves no worker behind within 5 s."""
    script = textwrap.dedent(f"""
        import sys, time
        sys.path.insert(0, {str(TESTS)!r})
        from worker_helpers import null_renderer
        from opaline.workers.pool import WorkerPool
        if __name__ == "__main__":
            pool = WorkerPool(null_renderer, workers=2)
            pool.start()
            print(" ".join(str(w["pid"]) for w in pool.status()), flush=True)
            time.sleep(60)
    """)
    owner = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    pids = [int(p) for p in owner.stdout.readline().split()]
    assert len(pids) == 2 and all(map(running, pids))
    owner.kill()
    owner.wait(5)
    end = time.monotonic() + 5
    while any(map(running, pids)) and time.monotonic() < end:
        time.sleep(0.05)
    assert not any(map(running, pids)), "a worker outlived its parent"
