"""bench/accuracy.py --merge: the last run's raw results, refused before the hour of
measuring where they cannot be merged into, and this run's presets put in their place."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RAW = ROOT / "bench" / "results" / "accuracy_grid.json"


def last_run(parser: argparse.ArgumentParser, args: argparse.Namespace) -> dict:
    """The results --merge keeps, refused before the hour of measuring, not after: none
    named, none there, or another size."""
    if not args.presets:
        parser.error("--merge needs --presets: the presets to measure again")
    if not RAW.is_file():
        parser.error(f"--merge: no last run to merge into ({RAW.relative_to(ROOT)})")
    last: dict = json.loads(RAW.read_text())
    labels = [p for programs in last["info"].get("programs", {}).values() for p in programs]
    if "compiled" not in last["info"] or not all(isinstance(p, str) for p in labels):
        parser.error("--merge: the last run's presets carry no program stamps as the table "
                     "lists them (measured before it did): measure every preset again")
    if last["info"]["size"] != args.size:
        parser.error(f"--merge: the last run was at {last['info']['size']}², "
                     f"this one would be at {args.size}²")
    return last


def merged(old: dict, new: dict, names: list[str]) -> dict:
    """The last run's results with ``names``' rows, facts and tier ratios from ``new``; the
    info is the last run's, with this run noted (what it measured, when, how long) in
    place of earlier merges whose presets it measured again."""
    keep = set(names)
    earlier = [m for m in old["info"].get("merged", [])
               if not ("presets" in m and set(m["presets"]) <= keep)]
    stamps = {key: {**old["info"][key], **new["info"][key]} for key in ("programs", "compiled")}
    info = {**old["info"], **stamps, "merged": [*earlier, {
        **{key: new["info"][key] for key in ("command", "date", "wall_s", "load")},
        "presets": sorted(keep)}]}
    return {"info": info,
            "rows": [r for r in old["rows"] if r["preset"] not in keep] + new["rows"],
            "facts": [f for f in old["facts"] if f["preset"] not in keep] + new["facts"],
            "tier_ratios": {**old.get("tier_ratios", {}), **new["tier_ratios"]}}
