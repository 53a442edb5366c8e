"""``opaline batch``: material files in, thumbnails out, reproducibly and incrementally.

    collect inputs (materials.collect) → plan (batch_plan: resolve, cache key, skip if
    up to date) → render (batch_pool: a GL thread, spawned processes, or a server)
    → write image, then sidecar (batch_plan) → summary JSON (+ contact sheet: sheet)

Ctrl-C or SIGTERM stops the run: work in flight is dropped, worker processes
end, temporary files are removed and the summary, marked interrupted, is
written with every item not reached as ``interrupted``.
"""

from __future__ import annotations

import json
import signal
import threading
import time
from collections import deque
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from opaline import __version__
from opaline.batch.plan import (
    Task,
    earlier_outputs,
    plan,
    prune,
    remove_temporaries,
    write_result,
)
from opaline.batch.pool import Outcome, start_pool
from opaline.batch.progress import PlainProgress, make_progress
from opaline.batch.shard import select
from opaline.batch.sheet import write_contact_sheet
from opaline.local.context import local_context
from opaline.model.materials import Item, collect
from opaline.output.files import write_atomic
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context
from opaline.settings import setting


class NothingToRender(ValueError):
    """The inputs hold no material file at all: a usage error, not an empty success."""


@dataclass
class Options:
    out: Path
    jobs: int = 1
    overrides: dict[str, Any] = field(default_factory=dict)
    server: str | None = None
    backend: str | None = None
    sheet: bool = False
    summary: Path | None = None
    force: bool = False
    retries: int = 5
    prune: bool = False  # remove outputs (with sidecars) whose material is gone
    quiet: bool = False  # no progress lines; failures are still told on stderr
    shard: tuple[int, int] | None = None  # (K, N): render shard K of N only (batch.shard)

    @property
    def summary_path(self) -> Path:
        return self.summary or self.out / "summary.json"


def run_batch(inputs: list[str | Path], options: Options,
              progress: PlainProgress | None = None) -> dict[str, Any]:
    """Render every input; returns the summary (also written to ``options.summary_path``)."""
    started = time.monotonic()
    items = collect(inputs, options.overrides,
                    exclude=[options.out, options.summary_path, *earlier_outputs(inputs)])
    if not items:
        shown = ", ".join(map(str, inputs))
        raise NothingToRender(f"no material files (.toml/.json) found in {shown}")
    # A folder that cannot be made is the batch's error, not each item's.
    options.out.mkdir(parents=True, exist_ok=True)
    # Every shard prunes against all items: the others' outputs are not "gone".
    tasks = plan(select(items, options.shard), options.out, force=options.force,
                 context=batch_context(options))
    progress = progress or make_progress(options.quiet)
    progress.start(tasks)
    try:
        render_all(tasks, options, progress)
    except KeyboardInterrupt:
        # A second Ctrl-C must not cut the clean-up short: the summary is written whole.
        with _signals(signal.SIG_IGN, signal.SIGINT, signal.SIGTERM):
            progress.close()
            for task in tasks:
                if task.status == "pending":
                    task.status = "interrupted"
            remove_temporaries(tasks, [options.summary_path])
            write_summary(tasks, options, started, interrupted=True)
        raise
    progress.close()
    pruned = prune_outputs(inputs, items, options, progress)
    summary = write_summary(tasks, options, started, interrupted=False, pruned=pruned)
    if options.sheet:
        write_contact_sheet(options.out, tasks)
    return summary


def batch_context(options: Options) -> Context:
    """With --server the server checks the cost, against its own budget, and finds the
    meshes (an upload's id or a file of its meshes folder): the plan keys the preset's own
    scene. Without, this machine's settings and mesh files."""
    if options.server:
        return Context(Limits(cost_budget=None), meshes=lambda request, preset: preset,
                       check_environments=False)
    return local_context(setting("cost_budget"))


def render_all(tasks: list[Task], options: Options, progress: PlainProgress) -> None:
    """Render every pending task, at most ``2 × jobs`` in flight; results are written here."""
    queue = deque(t for t in tasks if t.status == "pending")
    if not queue:
        return  # nothing to render: no GL context, no worker process
    pool = start_pool(options.jobs, options.backend, options.server, options.retries)
    pending: dict[Future[Outcome], Task] = {}
    try:
        while queue or pending:
            while queue and len(pending) < 2 * options.jobs:
                task = queue.popleft()
                pending[pool.submit(task)] = task
            done, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in done:
                task = pending.pop(future)
                finish(task, future)
                progress.advance(task)
    except BaseException:
        pool.abort()
        raise
    pool.close()


def finish(task: Task, future: Future[Outcome]) -> None:
    try:
        data, task.seconds, error = future.result()
    except Exception as exc:  # a worker process died (BrokenProcessPool) or similar
        data, error = None, f"worker failed: {type(exc).__name__}: {exc}"
    if data is None:
        task.status, task.error = "failed", f"{task.item.source}: {error}"
        return
    try:
        write_result(task, data)
    except OSError as exc:  # this item's output cannot be written: the others go on
        reason = exc.strerror or str(exc)
        task.status, task.error = "failed", f"{task.item.source}: cannot write {task.output}: {reason}"
        return
    task.status = "rendered"


def prune_outputs(inputs: list[str | Path], items: list[Item], options: Options,
                  progress: PlainProgress) -> list[str] | None:
    """--prune, unless an input is missing: a mistyped folder would otherwise look like
    every material gone, and prune every thumbnail."""
    if not options.prune:
        return None
    if not options.out.is_dir():
        return []
    missing = [str(p) for p in inputs if not Path(p).exists()]
    if missing:
        progress.line(f"not pruning: {', '.join(missing)} missing")
        return []
    removed = prune(options.out, {item.name for item in items})
    if removed:
        progress.line(f"pruned {len(removed)} file(s) of materials that are gone")
    return [str(p) for p in removed]


def write_summary(tasks: list[Task], options: Options, started: float,
                  interrupted: bool, pruned: list[str] | None = None) -> dict[str, Any]:
    counts = {s: sum(t.status == s for t in tasks) for s in ("rendered", "skipped", "failed")}
    if interrupted:
        counts["interrupted"] = sum(t.status == "interrupted" for t in tasks)
    summary: dict[str, Any] = {
        "opaline": __version__,
        "out": str(options.out),
        "server": options.server,
        "jobs": options.jobs,
        **({"shard": "{}/{}".format(*options.shard)} if options.shard else {}),
        "seconds": round(time.monotonic() - started, 3),
        "interrupted": interrupted,
        "counts": counts,
        "items": [t.record() for t in tasks],
    }
    if pruned is not None:
        summary["pruned"] = pruned
    text = json.dumps(summary, indent=2, ensure_ascii=False) + "\n"
    write_atomic(options.summary_path, text.encode())
    return summary


@contextmanager
def _signals(handler: Any, *signals: signal.Signals) -> Iterator[None]:
    """``handler`` for ``signals`` inside the block; only the main thread may set handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {sig: signal.signal(sig, handler) for sig in signals}
    try:
        yield
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old)


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt

