"""The batch's worker pools: spawned processes with a context each, ended at once on abort."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from opaline.batch.plan import Task
from opaline.batch.pool import GLProcesses, HttpThreads, start_pool
from opaline.model.materials import Item
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve


def test_worker_processes_are_spawned_not_forked():
    """--jobs N > 1 uses the spawn start method (a context made before a fork hangs, docs/design.md §10)."""
    pool = start_pool(jobs=2)
    try:
        assert pool.executor._mp_context.get_start_method() == "spawn"
    finally:
        pool.close()


def test_a_server_gets_http_threads_whatever_the_job_count():
    """With a server URL the pool sends requests; it makes no process and no GL context."""
    for jobs in (1, 3):
        pool = start_pool(jobs, server="http://127.0.0.1:1")
        try:
            assert isinstance(pool, HttpThreads) and pool.executor._max_workers == jobs
        finally:
            pool.close()


@pytest.mark.gl
def test_abort_ends_worker_processes_mid_render(backend):
    """abort() terminates the processes, the one busy with a long render included."""
    request = RenderRequest(preset="cd-rom", width=2048, height=2048, samples=256)
    task = Task(Item("heavy", "heavy", request), job=resolve(request, get_preset("cd-rom")))
    pool = GLProcesses(2, backend)
    future = pool.submit(task)
    deadline = time.monotonic() + 60
    while not pool.executor._processes:
        assert time.monotonic() < deadline, "no worker process started"
        time.sleep(0.05)
    processes = list(pool.executor._processes.values())
    time.sleep(2)  # past start-up: the render is under way
    assert not future.done(), "the render should still be running"
    pool.abort()
    deadline = time.monotonic() + 10
    while any(running(p.pid) for p in processes) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(running(p.pid) for p in processes), "a worker outlived abort()"


def running(pid: int) -> bool:
    """Whether the kernel still runs ``pid`` (a zombie has ended).

    Asked of /proc rather than Process.is_alive(): the executor's own thread also
    reaps its workers, and is_alive() reads "alive" when the other thread reaped first.
    """
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] not in ("Z", "X")
