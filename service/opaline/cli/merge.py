"""``opaline batch-merge``: the shards of a sharded batch (``--shard K/N``) as one batch.

    opaline batch mats --out thumbs --shard 1/2     # on one machine
    opaline batch mats --out thumbs --shard 2/2     # on another
    (copy both thumbs/ folders into one)
    opaline batch-merge thumbs/summary-*.json --out thumbs --sheet
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opaline.cli.args import CliError, write_output
from opaline.cli.batch import report_path
from opaline.output.files import write_atomic

if TYPE_CHECKING:
    from opaline.batch.plan import Task


def read_summary(path: str) -> dict[str, Any]:
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise CliError(f"{path}: not a readable batch summary: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("items"), list):
        raise CliError(f"{path}: not a batch summary (no items)")
    return data


def _missing_outputs(tasks: list[Task]) -> list[str]:
    missing = []
    for t in tasks:
        if t.written:
            assert t.output is not None  # a written item names its output file
            if not t.output.is_file():
                missing.append(str(t.output))
    return missing


def cmd_merge(args: argparse.Namespace) -> None:
    # Imported here: every command builds this parser; only batch-merge needs these.
    from opaline.batch.report import junit_xml
    from opaline.batch.shard import ShardError, merge_summaries, tasks_from_summary
    from opaline.batch.sheet import write_contact_sheet

    out = Path(args.out)
    report = report_path(args.report)
    try:
        merged = merge_summaries([read_summary(p) for p in args.summaries], out)
    except ShardError as exc:
        raise CliError(str(exc)) from None
    tasks = tasks_from_summary(merged)
    if args.sheet:
        missing = _missing_outputs(tasks)
        if missing:
            raise CliError(f"{len(missing)} output(s) missing from {out} (copy every shard's "
                           f"output folder into it first), e.g. {missing[0]}")
    summary_path = Path(args.summary) if args.summary else out / "summary.json"
    write_atomic(summary_path, (json.dumps(merged, indent=2, ensure_ascii=False) + "\n").encode())
    if args.sheet:
        write_contact_sheet(out, tasks)
    if report is not None:
        write_output(str(report), junit_xml(merged))
    counts = merged["counts"]
    print(f"opaline batch-merge: {merged['merged_shards']} shards, {counts['rendered']} rendered, "
          f"{counts['skipped']} skipped, {counts['failed']} failed; summary: {summary_path}",
          flush=True)
    if counts["failed"]:
        raise SystemExit(1)


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = sub.add_parser(
        "batch-merge", help="join the summaries (and contact sheet) of a sharded batch",
        description="Merge the summaries of every shard of `opaline batch --shard K/N` into "
                    "one, as an unsharded run writes it. Fails (2) if a shard is missing or "
                    "repeated; exit status 1 if any item failed.")
    parser.add_argument("summaries", nargs="+", metavar="SUMMARY",
                        help="each shard's summary JSON (any order)")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="the folder holding every shard's outputs")
    parser.add_argument("--summary", metavar="FILE",
                        help="merged summary (default DIR/summary.json)")
    parser.add_argument("--sheet", action="store_true",
                        help="also write DIR/index.html and DIR/sheet.png of every shard")
    parser.add_argument("--report", nargs=2, metavar=("junit", "FILE"),
                        help="also write a JUnit XML report of the whole batch")
    parser.set_defaults(func=cmd_merge)
