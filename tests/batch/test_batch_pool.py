"""The batch's worker pools: spawned processes with a context each, ended at once on abort."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from opaline.batch.plan import Task
from opaline.batch.pool import GLProcesses, HttpThreads, start_pool
from opaline.local.context import local_context
from opaline.model.materials import Item
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare
from opaline.workers.slot import SPAWN


@pytest.mark.gl
def test_worker_processes_are_spawned_not_forked(backend):
    """Local workers are spawned (a context made before a fork hangs, docs/design.md §10), not threads of ours."""
    pool = start_pool(jobs=2, backend=backend)
    try:
        assert SPAWN.get_start_method() == "spawn"
        pids = [w["pid"] for w in pool.pool.status()]
        assert len(set(pids)) == 2 and os.getpid() not in pids
        cmdlines = [Path(f"/proc/{pid}/cmdline").read_bytes() for pid in pids]
        assert all(b"multiprocessing.spawn" in c or b"spawn_main" in c for c in cmdlines)
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
    task = Task(Item("heavy", "heavy", request), prepared=prepare(request, local_context(None)))
    task.key = "heavy"
    pool = GLProcesses(2, backend)
    pids = [w["pid"] for w in pool.pool.status()]
    future = pool.submit(task)
    time.sleep(1)  # the render is under way
    assert not future.done(), "the render should still be running"
    pool.abort()
    deadline = time.monotonic() + 10
    while any(running(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(running(pid) for pid in pids), "a worker outlived abort()"


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
