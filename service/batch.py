"""``opaline batch``: material files in, thumbnails out, reproducibly and incrementally.

    collect inputs (materials.collect) → plan (batch_plan: resolve, cache key, skip if
    up to date) → render (batch_pool: a GL thread, spawned processes, or a server)
    → write image, then sidecar (batch_plan) → summary JSON (+ contact sheet: sheet)

Ctrl-C or SIGTERM stops the run: work in flight is dropped, worker processes
end, temporary files are removed and the summary, marked interrupted, is
written with every item not reached as ``interrupted``.
"""

from __future__ import annotations

import argparse
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
from typing import Any, get_args

from pydantic import ValidationError

from . import __version__
from .batch_plan import Task, plan, remove_temporaries, write_result
from .batch_pool import start_pool
from .cli import CliError, add_common, parse_size, write_atomic
from .materials import collect
from .params import ImageFormat, Quality, RenderRequest, describe_errors
from .pipeline import DEFAULT_COST_BUDGET
from .progress import PlainProgress, make_progress
from .sheet import write_contact_sheet


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

    @property
    def summary_path(self) -> Path:
        return self.summary or self.out / "summary.json"


def run_batch(inputs: list[str | Path], options: Options,
              progress: PlainProgress | None = None) -> dict[str, Any]:
    """Render every input; returns the summary (also written to ``options.summary_path``)."""
    started = time.monotonic()
    items = collect(inputs, options.overrides, exclude=[options.out, options.summary_path])
    # With --server the server checks the cost, against its own budget.
    budget = None if options.server else DEFAULT_COST_BUDGET
    tasks = plan(items, options.out, force=options.force, cost_budget=budget)
    progress = progress or make_progress()
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
    summary = write_summary(tasks, options, started, interrupted=False)
    if options.sheet:
        write_contact_sheet(options.out, tasks)
    return summary


def render_all(tasks: list[Task], options: Options, progress: PlainProgress) -> None:
    """Render every pending task, at most ``2 × jobs`` in flight; results are written here."""
    queue = deque(t for t in tasks if t.status == "pending")
    if not queue:
        return  # nothing to render: no GL context, no worker process
    pool = start_pool(options.jobs, options.backend, options.server, options.retries)
    pending: dict[Future, Task] = {}
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


def finish(task: Task, future: Future) -> None:
    try:
        data, task.seconds, error = future.result()
    except Exception as exc:  # a worker process died (BrokenProcessPool) or similar
        data, error = None, f"worker failed: {type(exc).__name__}: {exc}"
    if data is None:
        task.status, task.error = "failed", f"{task.item.source}: {error}"
        return
    write_result(task, data)
    task.status = "rendered"


def write_summary(tasks: list[Task], options: Options, started: float,
                  interrupted: bool) -> dict[str, Any]:
    counts = {s: sum(t.status == s for t in tasks) for s in ("rendered", "skipped", "failed")}
    if interrupted:
        counts["interrupted"] = sum(t.status == "interrupted" for t in tasks)
    summary = {
        "opaline": __version__,
        "out": str(options.out),
        "server": options.server,
        "jobs": options.jobs,
        "seconds": round(time.monotonic() - started, 3),
        "interrupted": interrupted,
        "counts": counts,
        "items": [t.record() for t in tasks],
    }
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


# Command line.

def cmd_batch(args: argparse.Namespace) -> None:
    options = options_from_args(args)
    with _signals(_raise_interrupt, signal.SIGTERM):  # SIGTERM stops a batch as Ctrl-C does
        summary = run_batch(args.inputs, options)
    counts = summary["counts"]
    print(f"opaline batch: {counts['rendered']} rendered, {counts['skipped']} skipped, "
          f"{counts['failed']} failed in {summary['seconds']:.1f} s; "
          f"summary: {options.summary_path}")
    if counts["failed"]:
        raise SystemExit(1)


def options_from_args(args: argparse.Namespace) -> Options:
    """The batch's options, every override and limit checked before any input is read."""
    overrides = overrides_from_args(args)
    if args.server and not args.server.startswith(("http://", "https://")):
        raise CliError(f"--server {args.server!r}: expected an http:// or https:// URL")
    jobs = args.jobs if args.jobs is not None else (4 if args.server else 1)
    if not 1 <= jobs <= 64:
        raise CliError(f"--jobs={jobs} is out of range: allowed [1 … 64]")
    # Per item, 100 retries wait at most about 17 minutes (the client caps a delay at 10 s).
    if not 0 <= args.retries <= 100:
        raise CliError(f"--retries={args.retries} is out of range: allowed [0 … 100]")
    return Options(out=Path(args.out), jobs=jobs, overrides=overrides, server=args.server,
                   backend=args.backend, sheet=args.sheet,
                   summary=Path(args.summary) if args.summary else None, force=args.force,
                   retries=args.retries)


def overrides_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """--size, --format and --quality as request fields, validated by the request model."""
    overrides: dict[str, Any] = {}
    if args.size:
        overrides["width"], overrides["height"] = parse_size(args.size)
    if args.format:
        overrides["format"] = args.format
    if args.quality:
        overrides["quality"] = args.quality
    try:
        RenderRequest.model_validate(overrides)
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc))) from None
    return overrides


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "batch", help="render folders of material files or manifests to thumbnails",
        description="Render material files (TOML/JSON), folders of them (recursive) and "
                    "manifests to DIR, skipping outputs that are up to date. Exit status 1 if "
                    "any input failed (all others are still rendered), 130 if interrupted.")
    parser.add_argument("inputs", nargs="+", metavar="INPUT",
                        help="material file, folder of material files, or *.manifest.toml/json")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--jobs", type=int, metavar="N",
                        help="parallel workers: GL processes locally (default 1), "
                             "HTTP requests with --server (default 4)")
    parser.add_argument("--format", choices=get_args(ImageFormat),
                        help="override every material's output format")
    parser.add_argument("--size", metavar="WxH", help="override every material's size")
    parser.add_argument("--quality", choices=get_args(Quality),
                        help="override every material's quality tier")
    parser.add_argument("--sheet", action="store_true",
                        help="also write DIR/index.html and DIR/sheet.png (a contact sheet)")
    parser.add_argument("--server", metavar="URL",
                        help="render on a running Opaline (POST URL/v1/render) instead of locally")
    parser.add_argument("--retries", type=int, default=5, metavar="N",
                        help="with --server: retries on 503 or connection errors, 0 … 100 "
                             "(default 5)")
    parser.add_argument("--summary", metavar="FILE",
                        help="machine-readable summary (default DIR/summary.json)")
    parser.add_argument("--force", action="store_true", help="render even if up to date")
    add_common(parser)
    parser.set_defaults(func=cmd_batch)
