"""Batch progress: a rich bar on a terminal, plain lines in logs and CI, or nothing (-q).

All report the same events: ``start`` with every planned task (the skipped
and the already failed are told at once), ``advance`` as each render ends,
``close`` at the end or on an interrupt. Each failure is also one line on
stderr (``failed: FILE[:LINE]: why``), whatever the progress shows, so CI
logs and ``2>`` catch them.
"""

from __future__ import annotations

import os
import sys
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from opaline.batch.plan import Task


def use_rich(stream: Any, env: Any = os.environ) -> bool:
    in_ci = env.get("CI", "").strip().lower() not in ("", "0", "false", "no")
    return bool(getattr(stream, "isatty", lambda: False)()) and not in_ci


class PlainProgress:
    """One line per finished item, with the rate and the time left."""

    def __init__(self, stream: Any = None, errors: Any = None) -> None:
        self.stream = stream or sys.stdout
        self.errors = errors or sys.stderr
        self.total = self.done = 0
        self.started = time.monotonic()

    def start(self, tasks: list[Task]) -> None:
        self.total = sum(t.status == "pending" for t in tasks)
        self.started = time.monotonic()
        skipped = sum(t.status == "skipped" for t in tasks)
        if skipped:
            self.line(f"skipped {skipped} up to date")
        for task in tasks:
            if task.status == "failed":
                self.failed(task)
        if self.total:
            self.line(f"rendering {self.total} of {len(tasks)}")

    def advance(self, task: Task) -> None:
        self.done += 1
        rate = self.done / max(time.monotonic() - self.started, 1e-9)
        eta = (self.total - self.done) / rate
        width = len(str(self.total))
        text = f"[{self.done:>{width}}/{self.total}] {task.status:<8} {task.item.name}"
        if task.status == "failed":
            self.failed(task)
        self.line(f"{text} ({task.seconds:.2f} s; {rate:.2f}/s, ETA {eta:.0f} s)")

    def failed(self, task: Task) -> None:
        error = " ".join((task.error or "failed").split())  # a shader log has newlines
        print(f"failed: {error}", file=self.errors, flush=True)

    def line(self, text: str) -> None:
        print(text, file=self.stream, flush=True)

    def close(self) -> None:
        pass


class QuietProgress(PlainProgress):
    """-q: nothing but the failures (on stderr)."""

    def line(self, text: str) -> None:
        pass


class RichProgress(PlainProgress):
    """A progress bar with the count, the rate and the ETA; failures printed above it."""

    def start(self, tasks: list[Task]) -> None:
        from rich.console import Console

        self.bar = _bar(Console(file=self.stream))
        super().start(tasks)
        self.bar_task = self.bar.add_task("rendering", total=self.total)
        self.bar.start()

    def advance(self, task: Task) -> None:
        if task.status == "failed":
            self.failed(task)
        self.bar.advance(self.bar_task)

    def failed(self, task: Task) -> None:
        if self.errors is self.stream:  # above the bar, not through it
            self.line(f"failed: {' '.join((task.error or 'failed').split())}")
        else:
            super().failed(task)

    def line(self, text: str) -> None:
        self.bar.console.print(text, markup=False, highlight=False, soft_wrap=True)

    def close(self) -> None:
        self.bar.stop()


def _bar(console: Any) -> Any:
    """rich's Progress with the columns: description, bar, count, rate, elapsed, ETA."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        ProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )
    from rich.text import Text

    class RateColumn(ProgressColumn):
        def render(self, task: Any) -> Text:
            speed = task.finished_speed or task.speed
            return Text(f"{speed:.1f}/s" if speed else "–/s", style="progress.data.speed")

    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                    RateColumn(), TimeElapsedColumn(), TextColumn("ETA"),
                    TimeRemainingColumn(), console=console)


def make_progress(quiet: bool = False) -> PlainProgress:
    """The bar on stderr when it is a terminal (outside CI), else plain lines on stdout;
    with ``quiet`` only the failures."""
    if quiet:
        return QuietProgress(sys.stdout)
    return RichProgress(sys.stderr) if use_rich(sys.stderr) else PlainProgress(sys.stdout)
