"""Sharded batches: ``opaline batch --shard K/N`` and the merge of the shards' summaries.

A CI matrix of N jobs each renders a stable 1/N of the inputs: an item belongs
to shard ``1 + hash(name) mod N``, where the name is its output path below the
output folder (a material file's path below its input folder, a manifest
entry's name). The hash is of the name alone, so adding, removing or
reordering inputs never moves another item to another shard (each shard's
outputs stay up to date), and every machine computes the same split.

The merge takes the N summaries (outputs copied into one folder: their names
do not overlap) and writes one summary, in the unsharded run's form, and its
contact sheet.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from opaline import __version__
from opaline.batch.plan import Task
from opaline.model.materials import Item

SHARD_RE = re.compile(r"^\s*(\d+)\s*/\s*(\d+)\s*$")
MAX_SHARDS = 10_000


class ShardError(ValueError):
    """A malformed --shard, or summaries that do not make up one whole batch."""


def parse_shard(text: str) -> tuple[int, int]:
    """'K/N' → (K, N), 1 ≤ K ≤ N ≤ MAX_SHARDS (K counts from 1, as a CI matrix does)."""
    found = SHARD_RE.match(text)
    if found is None:
        raise ShardError(f"--shard {text!r}: expected K/N, e.g. 1/4")
    k, n = int(found.group(1)), int(found.group(2))
    if not 1 <= n <= MAX_SHARDS or not 1 <= k <= n:
        raise ShardError(f"--shard {text}: need 1 ≤ K ≤ N ≤ {MAX_SHARDS}")
    return k, n


def shard_of(name: str, count: int) -> int:
    """The shard (1 … count) of the item named ``name``; case-folded as names are unique."""
    digest = hashlib.sha256(name.lower().encode()).digest()
    return 1 + int.from_bytes(digest[:8], "big") % count


def select(items: list[Item], shard: tuple[int, int] | None) -> list[Item]:
    """The items of ``shard`` (all of them without one), in their order."""
    if shard is None:
        return items
    k, n = shard
    return [item for item in items if shard_of(item.name, n) == k]


# Merging

STATUSES = ("rendered", "skipped", "failed")


def merge_summaries(summaries: Sequence[dict[str, Any]], out: Path) -> dict[str, Any]:
    """One summary for the whole batch from its N shards' (any order): items by name, each
    output path moved into ``out``; wall time is the slowest shard's."""
    shards = sorted(_shard_numbers(summaries))
    items: dict[str, dict[str, Any]] = {}
    for summary in summaries:
        for record in summary["items"]:
            if record["name"].lower() in items:
                raise ShardError(f"{record['name']!r} is in two summaries")
            items[record["name"].lower()] = _moved(record, Path(summary["out"]), out)
    ordered = [items[name] for name in sorted(items)]
    interrupted = any(s.get("interrupted") for s in summaries)
    counts = {s: sum(r["status"] == s for r in ordered) for s in STATUSES}
    if interrupted:
        counts["interrupted"] = sum(r["status"] == "interrupted" for r in ordered)
    merged: dict[str, Any] = {
        "opaline": __version__, "out": str(out), "server": summaries[0].get("server"),
        "jobs": summaries[0].get("jobs"),
        "seconds": max(float(s.get("seconds", 0.0)) for s in summaries),
        "interrupted": interrupted, "counts": counts, "items": ordered,
        "merged_shards": len(shards)}
    pruned = [p for s in summaries for p in s.get("pruned") or []]
    if any("pruned" in s for s in summaries):
        merged["pruned"] = sorted(set(pruned))
    return merged


def _shard_numbers(summaries: Sequence[dict[str, Any]]) -> list[int]:
    """Every shard 1 … N exactly once, all of one N: a missing shard is an error, not a
    smaller batch."""
    if not summaries:
        raise ShardError("no summaries to merge")
    given = [parse_shard(s["shard"]) if s.get("shard") else None for s in summaries]
    found = [shard for shard in given if shard is not None]
    if len(found) < len(given):
        raise ShardError("a summary is not from a sharded run (no \"shard\" in it)")
    counts = {n for _, n in found}
    if len(counts) != 1:
        raise ShardError(f"summaries from different shard counts: {sorted(counts)}")
    total = counts.pop()
    numbers = sorted(k for k, _ in found)
    if numbers != list(range(1, total + 1)):
        missing = sorted(set(range(1, total + 1)) - set(numbers))
        repeated = sorted({k for k in numbers if numbers.count(k) > 1})
        raise ShardError(f"shards of {total}: missing {missing}, repeated {repeated}")
    return numbers


def _moved(record: dict[str, Any], old_out: Path, out: Path) -> dict[str, Any]:
    """``record`` with its output path under ``out`` instead of its shard's folder."""
    record = dict(record)
    if record.get("output"):
        output = Path(record["output"])
        rel = output.relative_to(old_out) if output.is_relative_to(old_out) else output.name
        record["output"] = str(out / rel)
    return record


def tasks_from_summary(summary: dict[str, Any]) -> list[Task]:
    """Enough of each item's task for the contact sheet (``sheet.write_contact_sheet``)."""
    return [Task(Item(r["name"], r["input"], file=r.get("file"), line=r.get("line")),
                 key=r.get("key"), output=Path(r["output"]) if r.get("output") else None,
                 status=r["status"], seconds=r.get("seconds", 0.0), error=r.get("error"))
            for r in summary["items"]]
