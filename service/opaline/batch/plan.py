"""A batch's plan and its outputs on disk: what each item renders to, and whether it is current.

Each output ``DIR/NAME.png`` has a sidecar ``DIR/NAME.png.json`` holding the
cache key of its resolved request (``Job.cache_key``: request, preset scene,
shader sources, version); the same key means the image is up to date. The
sidecar is written after the image, so a pair cut short re-renders.
"""

from __future__ import annotations

import glob
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opaline import __version__
from opaline.local.context import local_context
from opaline.model.material_file import at, locate
from opaline.model.materials import Item
from opaline.model.meshes import MeshFileMissing
from opaline.model.presets import UnknownPreset
from opaline.model.request import CostError, Job
from opaline.output.encode import EXTENSIONS
from opaline.output.files import write_atomic
from opaline.pipeline.limits import LimitError
from opaline.pipeline.prepare import Context, Prepared, UnknownEnvironment, prepare

WRITTEN = ("rendered", "skipped")  # the statuses with an output on disk


@dataclass
class Task:
    """One item's fate: where it goes, its key, and what happened."""

    item: Item
    prepared: Prepared | None = None
    key: str | None = None
    output: Path | None = None
    status: str = "pending"  # → rendered | skipped | failed | interrupted
    seconds: float = 0.0
    error: str | None = None

    @property
    def job(self) -> Job | None:
        return None if self.prepared is None else self.prepared.job

    @property
    def sidecar(self) -> Path:
        assert self.output is not None
        return self.output.with_name(self.output.name + ".json")

    @property
    def written(self) -> bool:
        return self.status in WRITTEN

    def record(self) -> dict[str, Any]:
        return {"name": self.item.name, "input": self.item.source,
                "output": str(self.output) if self.written else None,
                "status": self.status, "seconds": round(self.seconds, 4), "error": self.error,
                "key": self.key, "file": self.item.file, "line": self.item.line}


def plan(items: list[Item], out: Path, *, force: bool = False,
         cost_budget: int | None = None, context: Context | None = None) -> list[Task]:
    """A task per item, prepared against ``context`` (default: this machine's, with
    ``cost_budget``; ``None`` leaves the cost check to the server that renders)."""
    context = context or local_context(cost_budget)
    return [plan_one(item, out, force, context) for item in items]


def plan_one(item: Item, out: Path, force: bool, context: Context) -> Task:
    task = Task(item)
    if item.request is None:
        task.status, task.error = "failed", item.error
        return task
    try:
        task.prepared = prepare(item.request, context)
    except (UnknownPreset, CostError, LimitError, UnknownEnvironment, MeshFileMissing) as exc:
        if isinstance(exc, UnknownPreset) and item.file == item.source:  # a material file
            item.line = locate(item.file, "preset")
        task.status, task.error = "failed", f"{at(item.source, item.line)}: {exc}"
        return task
    task.key = task.prepared.key
    task.output = out / (item.name + EXTENSIONS[task.prepared.job.format])
    if not force and up_to_date(task):
        task.status = "skipped"
    return task


def up_to_date(task: Task) -> bool:
    if task.output is None or not task.output.is_file():
        return False
    try:
        recorded: object = json.loads(task.sidecar.read_text()).get("key")
        return recorded == task.key
    except (OSError, ValueError, AttributeError):  # unreadable, not JSON, not a JSON object
        return False


def write_result(task: Task, data: bytes) -> None:
    """The image first, then its sidecar: an interrupted pair is not up to date."""
    assert task.output is not None and task.item.request is not None
    write_atomic(task.output, data)
    sidecar = {"key": task.key, "input": task.item.source, "opaline": __version__,
               "request": task.item.request.model_dump(mode="json", exclude_none=True)}
    write_atomic(task.sidecar, (json.dumps(sidecar, indent=2) + "\n").encode())


def remove_temporaries(tasks: list[Task], extra: list[Path]) -> None:
    """Temporary files ``write_atomic`` may have left for these outputs: a signal that lands
    between its ``mkstemp`` and its ``try`` leaves one that its own cleanup never sees."""
    paths = [p for t in tasks if t.output for p in (t.output, t.sidecar)] + extra
    for path in paths:
        for tmp in path.parent.glob(f".{glob.escape(path.name)}.*.tmp"):
            tmp.unlink(missing_ok=True)


def prune(out: Path, names: set[str]) -> list[Path]:
    """Remove the outputs in ``out`` whose item is gone, with their sidecars; returns them.

    Only pairs this batch wrote are touched: an image beside a sidecar holding a cache
    key. ``names`` are every item's name, failed ones included (a material that now
    fails still exists)."""
    known = {name.lower() for name in names}
    removed: list[Path] = []
    for sidecar in sorted(out.rglob("*.json")):
        image = sidecar.with_suffix("")  # NAME.png.json → NAME.png
        if image.suffix not in EXTENSIONS.values() or not _is_sidecar(sidecar):
            continue
        if image.relative_to(out).with_suffix("").as_posix().lower() in known:
            continue
        for path in (image, sidecar):
            if path.is_file():
                path.unlink()
                removed.append(path)
        _remove_empty_parents(image.parent, out)
    return removed


def earlier_outputs(inputs: list[str | Path]) -> list[Path]:
    """What earlier batches wrote inside input folders: their summaries, the output folders
    those name, and sidecars wherever they are: JSON, but no material files (a second
    batch of a folder over its first's read them and failed). A summary written among the
    inputs (``--summary``) excludes itself, not its folder."""
    found = []
    for folder in (Path(raw) for raw in inputs if Path(raw).is_dir()):
        for path in folder.rglob("*.json"):  # one walk; a sidecar is read once
            if path.with_suffix("").suffix in EXTENSIONS.values() and _is_sidecar(path):
                found.append(path.resolve())
            elif (out := _summary_out(path)) is not None:
                found += [path.resolve(), out.resolve()]
    return found


def _summary_out(path: Path) -> Path | None:
    """The output folder a batch summary names, or None where ``path`` is none."""
    try:
        found = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(found, dict) or not {"opaline", "items", "counts", "out"} <= found.keys():
        return None
    if not isinstance(found["out"], str):
        return None
    out = Path(found["out"])
    # Written as given to --out: relative to where that batch ran, unknown here, except
    # where the summary sits in it, as it does by default.
    if not out.is_absolute() and path.name == "summary.json" and path.parent.name == out.name:
        return path.parent
    return out


def _is_sidecar(path: Path) -> bool:
    try:
        return "key" in json.loads(path.read_text())
    except (OSError, ValueError, TypeError):
        return False


def _remove_empty_parents(folder: Path, out: Path) -> None:
    while folder != out and folder.is_relative_to(out) and not any(folder.iterdir()):
        folder.rmdir()
        folder = folder.parent
