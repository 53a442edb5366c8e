"""``opaline batch``: material files in, thumbnails out, reproducibly and incrementally.

    collect inputs (materials.collect) → plan (resolve, cache key, skip if up to date)
    → render (a worker thread, spawn-started processes, or a server) → write atomically
    → summary JSON (+ contact sheet)

Each output ``DIR/NAME.png`` has a sidecar ``DIR/NAME.png.json`` holding the
cache key of its resolved request (``Job.cache_key``: request, preset scene,
shader sources, version); the same key means the image is up to date. The
sidecar is written after the image, so a pair cut short re-renders. Worker
processes use the ``spawn`` start method and make their GL context inside
the worker (DESIGN §8).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import signal
import threading
import time
from collections import deque
from concurrent.futures import (
    FIRST_COMPLETED,
    Executor,
    Future,
    ProcessPoolExecutor,
    ThreadPoolExecutor,
    wait,
)
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from . import __version__
from .cli import CliError, parse_size, write_atomic
from .encode import EXTENSIONS
from .materials import Item, collect
from .params import RenderRequest, describe_errors
from .pipeline import DEFAULT_COST_BUDGET
from .presets import UnknownPreset, get_preset
from .progress import PlainProgress, make_progress
from .progress import RichProgress as RichProgress  # re-exported: batch.RichProgress
from .progress import use_rich as use_rich  # re-exported: batch.use_rich
from .request import CostError, Job, check_cost, resolve
from .sheet import THUMB as THUMB  # re-exported: batch.THUMB
from .sheet import write_contact_sheet


@dataclass
class Task:
    """One item's fate: where it goes, its key, and what happened."""

    item: Item
    job: Job | None = None
    key: str | None = None
    output: Path | None = None
    status: str = "pending"  # → rendered | skipped | failed | interrupted
    seconds: float = 0.0
    error: str | None = None

    @property
    def sidecar(self) -> Path:
        assert self.output is not None
        return self.output.with_name(self.output.name + ".json")

    def record(self) -> dict[str, Any]:
        return {"name": self.item.name, "input": self.item.source,
                "output": str(self.output) if self.status in ("rendered", "skipped") else None,
                "status": self.status, "seconds": round(self.seconds, 4), "error": self.error,
                "key": self.key}


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


# Planning: validate, resolve, decide what is up to date.

def plan(items: list[Item], options: Options) -> list[Task]:
    return [plan_one(item, options) for item in items]


def plan_one(item: Item, options: Options) -> Task:
    task = Task(item)
    if item.request is None:
        task.status, task.error = "failed", item.error
        return task
    try:
        preset = get_preset(item.request.preset)
        task.job = resolve(item.request, preset)
        if options.server is None:
            check_cost(task.job, DEFAULT_COST_BUDGET)
    except (UnknownPreset, CostError) as exc:
        task.status, task.error = "failed", f"{item.source}: {exc}"
        return task
    task.key = task.job.cache_key(preset.scene_key())
    task.output = options.out / (item.name + EXTENSIONS[task.job.format])
    if not options.force and up_to_date(task):
        task.status = "skipped"
    return task


def up_to_date(task: Task) -> bool:
    if task.output is None or not task.output.is_file():
        return False
    try:
        return json.loads(task.sidecar.read_text()).get("key") == task.key
    except (OSError, ValueError, AttributeError):
        return False


def write_result(task: Task, data: bytes) -> None:
    """The image first, then its sidecar: an interrupted pair is not up to date."""
    assert task.output is not None and task.item.request is not None
    write_atomic(task.output, data)
    sidecar = {"key": task.key, "input": task.item.source, "opaline": __version__,
               "request": task.item.request.model_dump(mode="json", exclude_none=True)}
    write_atomic(task.sidecar, (json.dumps(sidecar, indent=2) + "\n").encode())


def remove_temporaries(tasks: list[Task], extra: list[Path]) -> None:
    """Temporary files ``write_atomic`` may have left for these outputs."""
    paths = [p for t in tasks if t.output for p in (t.output, t.sidecar)] + extra
    for path in paths:
        for tmp in path.parent.glob(f".{path.name}.*.tmp"):
            tmp.unlink(missing_ok=True)


# Workers. Each returns (data, seconds, error) so that no exception has to cross a process.

def _render_local(job: Job, backend: str | None) -> tuple[bytes | None, float, str | None]:
    from . import api_python

    start = time.perf_counter()
    try:
        data = api_python.render_job(job, backend=backend)
    except Exception as exc:  # a shader or context failure fails this item, not the batch
        return None, time.perf_counter() - start, f"{type(exc).__name__}: {exc}"
    return data, time.perf_counter() - start, None


def _init_process(backend: str | None, lp_threads: int) -> None:
    """In a spawned worker: the parent handles Ctrl-C; share the cores between llvmpipes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if lp_threads > 0:
        os.environ.setdefault("LP_NUM_THREADS", str(lp_threads))
    _warm_up(backend)


def _warm_up(backend: str | None) -> None:
    """Make this worker's GL context now, so that item times are render times."""
    from . import api_python

    try:
        api_python.renderer(backend)
    except Exception:  # each item's render reports the failure with its message
        pass


def _render_remote(remote: Any, task: Task) -> tuple[bytes | None, float, str | None]:
    from .client import RemoteError

    start = time.perf_counter()
    try:
        data = remote.render(task.item.request)
    except RemoteError as exc:
        return None, time.perf_counter() - start, str(exc)
    return data, time.perf_counter() - start, None


class Workers:
    """A pool that renders tasks: one thread, spawned processes, or HTTP threads."""

    def __init__(self, options: Options) -> None:
        self.options = options
        self.remote = None
        self.executor: Executor
        if options.server:
            from .client import RemoteRenderer

            self.remote = RemoteRenderer(options.server, jobs=options.jobs, retries=options.retries)
            self.executor = ThreadPoolExecutor(options.jobs, thread_name_prefix="opaline-http")
        elif options.jobs == 1:
            self.executor = ThreadPoolExecutor(1, thread_name_prefix="opaline-gl",
                                               initializer=_warm_up, initargs=(options.backend,))
        else:
            lp_threads = max(1, (os.cpu_count() or 1) // options.jobs)
            self.executor = ProcessPoolExecutor(
                options.jobs, mp_context=multiprocessing.get_context("spawn"),
                initializer=_init_process, initargs=(options.backend, lp_threads))

    def submit(self, task: Task) -> Future:
        if self.remote is not None:
            return self.executor.submit(_render_remote, self.remote, task)
        return self.executor.submit(_render_local, task.job, self.options.backend)

    def close(self) -> None:
        if isinstance(self.executor, ThreadPoolExecutor) and self.remote is None:
            from . import api_python

            self.executor.submit(api_python.close)  # the GL thread releases its own context
        self.executor.shutdown(wait=True)
        if self.remote is not None:
            self.remote.close()

    def abort(self) -> None:
        """Stop now: drop queued work and end worker processes."""
        self.executor.shutdown(wait=False, cancel_futures=True)
        for process in list((getattr(self.executor, "_processes", None) or {}).values()):
            process.terminate()
        if self.remote is not None:
            self.remote.close()


def render_all(tasks: list[Task], options: Options, progress: Any) -> None:
    """Render every pending task, at most ``2 × jobs`` in flight; results are written here."""
    queue = deque(t for t in tasks if t.status == "pending")
    if not queue:
        return  # nothing to render: no GL context, no worker process
    workers = Workers(options)
    pending: dict[Future, Task] = {}
    try:
        while queue or pending:
            while queue and len(pending) < 2 * options.jobs:
                task = queue.popleft()
                pending[workers.submit(task)] = task
            done, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in done:
                task = pending.pop(future)
                finish(task, future)
                progress.advance(task)
    except BaseException:
        workers.abort()
        raise
    workers.close()


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


# The run.

def run_batch(inputs: list[str | Path], options: Options,
              progress: PlainProgress | None = None) -> dict[str, Any]:
    """Render every input; returns the summary (also written to ``options.summary``)."""
    started = time.monotonic()
    summary_path = options.summary or options.out / "summary.json"
    items = collect(inputs, options.overrides, exclude=[options.out, summary_path])
    tasks = plan(items, options)
    progress = progress or make_progress()
    progress.start(tasks)
    try:
        render_all(tasks, options, progress)
    except KeyboardInterrupt:
        with _shielded():
            progress.close()
            for task in tasks:
                task.status = "interrupted" if task.status == "pending" else task.status
            remove_temporaries(tasks, [summary_path])
            write_summary(summary_path, tasks, options, started, interrupted=True)
        raise
    progress.close()
    summary = write_summary(summary_path, tasks, options, started, interrupted=False)
    if options.sheet:
        write_contact_sheet(options.out, tasks)
    return summary


def write_summary(path: Path, tasks: list[Task], options: Options, started: float,
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
    write_atomic(path, (json.dumps(summary, indent=2, ensure_ascii=False) + "\n").encode())
    return summary


class _shielded:
    """Ignore SIGINT and SIGTERM while cleaning up after an interrupt (main thread only)."""

    def __enter__(self) -> None:
        self.saved = {}
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.saved[sig] = signal.signal(sig, signal.SIG_IGN)

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self.saved.items():
            signal.signal(sig, handler)


class _term_as_interrupt:
    """SIGTERM stops a batch the way Ctrl-C does (main thread only)."""

    def __enter__(self) -> None:
        self.saved = None
        if threading.current_thread() is threading.main_thread():
            self.saved = signal.signal(signal.SIGTERM, _raise_interrupt)

    def __exit__(self, *exc: object) -> None:
        if self.saved is not None:
            signal.signal(signal.SIGTERM, self.saved)


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


# Command line.

def cmd_batch(args: argparse.Namespace) -> None:
    options = options_from_args(args)
    with _term_as_interrupt():
        summary = run_batch(args.inputs, options)
    counts = summary["counts"]
    where = options.summary or options.out / "summary.json"
    print(f"opaline batch: {counts['rendered']} rendered, {counts['skipped']} skipped, "
          f"{counts['failed']} failed in {summary['seconds']:.1f} s; summary: {where}")
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
    parser.add_argument("--format", choices=["png", "png16", "npy"],
                        help="override every material's output format")
    parser.add_argument("--size", metavar="WxH", help="override every material's size")
    parser.add_argument("--quality", choices=["draft", "standard", "high", "reference"],
                        help="override every material's quality tier")
    parser.add_argument("--sheet", action="store_true",
                        help="also write DIR/index.html and DIR/sheet.png (a contact sheet)")
    parser.add_argument("--server", metavar="URL",
                        help="render on a running Opaline (POST URL/v1/render) instead of locally")
    parser.add_argument("--retries", type=int, default=5, metavar="N",
                        help="with --server: retries on 503 or connection errors (default 5)")
    parser.add_argument("--summary", metavar="FILE",
                        help="machine-readable summary (default DIR/summary.json)")
    parser.add_argument("--force", action="store_true", help="render even if up to date")
    parser.add_argument("--backend", choices=["egl", "osmesa", "auto"], default=None,
                        help="headless GL backend (default: $OPALINE_GL_BACKEND or egl)")
    parser.set_defaults(func=cmd_batch)
