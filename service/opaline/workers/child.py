"""The worker process: one GL context, jobs in over a pipe, encoded bytes out.

Started with the ``spawn`` method (a GL context made before a fork hangs the
children's contexts). It dies with its parent however the parent dies: the
kernel's parent-death signal, and a watcher thread for the moment between
the spawn and that signal being armed. A render that raises anything but a
shader error may have broken the context, so the worker answers, then exits,
and the pool starts a fresh one.
"""

from __future__ import annotations

import ctypes
import logging
import os
import signal
import threading
import time
import traceback
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from typing import Any

PR_SET_PDEATHSIG = 1
PARENT_POLL_S = 0.5
HEARTBEAT_S = 0.5  # the supervisor calls a worker hung after a few missed beats (slot.py)

log = logging.getLogger(__name__)


@dataclass
class Reply:
    job_id: int
    data: bytes | None = None
    error: str = ""
    kind: str = "ok"  # ok, cancelled, shader, crash
    seconds: float = 0.0
    rss_bytes: int = 0
    stats: dict[str, int] = field(default_factory=dict)


def rss_bytes(pid: int | str = "self") -> int:
    """Resident set size from /proc (0 where there is none)."""
    try:
        with open(f"/proc/{pid}/statm") as statm:
            return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def cpu_ticks(pid: int) -> int:
    """User and system CPU time of a process and its threads, in clock ticks (-1 if gone)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        return int(fields[11]) + int(fields[12])
    except (OSError, ValueError, IndexError):
        return -1


def die_with_parent(parent_pid: int) -> None:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass  # not Linux: the watcher below still ends us

    def watch() -> None:
        while True:
            if os.getppid() != parent_pid:
                os._exit(0)
            time.sleep(PARENT_POLL_S)

    threading.Thread(target=watch, name="opaline-parent-watch", daemon=True).start()


def beat(heartbeat: Any) -> None:
    """Stamp the shared clock (CLOCK_MONOTONIC is the machine's, the same in the parent)
    from a thread of its own, so that a worker busy rendering still beats."""
    def loop() -> None:
        while True:
            heartbeat.value = time.monotonic()
            time.sleep(HEARTBEAT_S)

    threading.Thread(target=loop, name="opaline-heartbeat", daemon=True).start()


def main(conn: Connection, factory: Any, parent_pid: int, lp_threads: int | None,
         cancel: Any, heartbeat: Any = None) -> None:
    """The worker's whole life: make the context, answer jobs until told to stop."""
    die_with_parent(parent_pid)
    if heartbeat is not None:
        beat(heartbeat)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    if lp_threads:
        os.environ["LP_NUM_THREADS"] = str(lp_threads)  # llvmpipe reads it at context creation
    from opaline.scene.parse_memory import limit_parse_memory
    limit_parse_memory()  # a mesh parse here has a hard memory ceiling (422 past it)
    try:
        renderer = factory()
        gl = getattr(renderer, "gl", None)
        info = gl.describe() if gl is not None else {}
    except Exception as exc:  # any failure leaves this worker without GL
        conn.send(("failed", f"{type(exc).__name__}: {exc}"))
        return
    conn.send(("ready", info))
    try:
        serve(conn, renderer, cancel)
    finally:
        try:
            renderer.release()
        except Exception:  # a lost context may not release cleanly; the process ends anyway
            pass


def serve(conn: Connection, renderer: Any, cancel: Any) -> None:
    from opaline.gl.buffers import Cancelled
    from opaline.gl.shaders import ShaderError
    from opaline.scene.environment_files import EnvironmentMapError
    from opaline.scene.meshfile import MeshError

    def should_stop() -> bool:
        return bool(cancel.value)

    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        job_id, task = message
        start = time.perf_counter()
        reply = Reply(job_id)
        crashed = False
        try:
            reply.data = task.run(renderer, should_stop)
        except Cancelled as exc:
            reply.kind, reply.error = "cancelled", str(exc)
        except ShaderError as exc:
            reply.kind, reply.error = "shader", str(exc)
        except (MeshError, EnvironmentMapError) as exc:  # the user's file, not the worker
            reply.kind, reply.error = "invalid", str(exc)
        except Exception:  # GL errors, lost contexts, anything the draw raised
            reply.kind, reply.error = "crash", traceback.format_exc()
            crashed = True
        reply.seconds = time.perf_counter() - start
        reply.rss_bytes = rss_bytes()
        stats = getattr(renderer, "cache_stats", None)
        reply.stats = stats() if stats is not None else {}
        conn.send(reply)
        if crashed:
            return
