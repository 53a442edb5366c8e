"""``opaline batch``: the command line of the batch renderer (``opaline.batch.run``)."""

from __future__ import annotations

import argparse
import os
import signal
from pathlib import Path
from typing import TYPE_CHECKING, Any, get_args

from pydantic import ValidationError

from opaline.cli.args import CliError, add_common, parse_size, write_output
from opaline.model.params import ImageFormat, Quality, RenderRequest, describe_errors

if TYPE_CHECKING:
    from opaline.batch.run import Options


def cmd_batch(args: argparse.Namespace) -> None:
    # Imported here: `opaline render` builds this parser too and must not pay for batch.
    from opaline.batch.report import github_annotations, junit_xml
    from opaline.batch.run import NothingToRender, _raise_interrupt, _signals, run_batch

    options = options_from_args(args)
    report = report_path(args.report)
    with _signals(_raise_interrupt, signal.SIGTERM):  # SIGTERM stops a batch as Ctrl-C does
        try:
            summary = run_batch(args.inputs, options)
        except NothingToRender as exc:
            raise CliError(str(exc)) from None
    if report is not None:
        write_output(str(report), junit_xml(summary))
    if os.environ.get("GITHUB_ACTIONS") == "true":  # annotations on the failed files' lines
        for line in github_annotations(summary):
            print(line, flush=True)
    counts = summary["counts"]
    if not args.quiet:
        print(f"opaline batch: {counts['rendered']} rendered, {counts['skipped']} skipped, "
              f"{counts['failed']} failed in {summary['seconds']:.1f} s; "
              f"summary: {options.summary_path}", flush=True)
    if counts["failed"]:
        raise SystemExit(1)


def report_path(report: list[str] | None) -> Path | None:
    """--report KIND FILE; JUnit XML is the kind every CI reads."""
    if report is None:
        return None
    kind, path = report
    if kind != "junit":
        raise CliError(f"--report {kind}: unknown report kind (known: junit)")
    return Path(path)


def options_from_args(args: argparse.Namespace) -> Options:
    """The batch's options, every override and limit checked before any input is read."""
    from opaline.batch.run import Options
    from opaline.batch.shard import ShardError, parse_shard

    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise CliError(f"--out {args.out}: not a folder (a file of that name is in the way)")
    overrides = overrides_from_args(args)
    if args.server and not args.server.startswith(("http://", "https://")):
        raise CliError(f"--server {args.server!r}: expected an http:// or https:// URL")
    jobs = args.jobs if args.jobs is not None else (4 if args.server else 1)
    if not 1 <= jobs <= 64:
        raise CliError(f"--jobs={jobs} is out of range: allowed [1 … 64]")
    # Per item, 100 retries wait at most about 17 minutes (the client caps a delay at 10 s).
    if not 0 <= args.retries <= 100:
        raise CliError(f"--retries={args.retries} is out of range: allowed [0 … 100]")
    try:
        shard = parse_shard(args.shard) if args.shard else None
    except ShardError as exc:
        raise CliError(str(exc)) from None
    return Options(out=Path(args.out), jobs=jobs, overrides=overrides, server=args.server,
                   backend=args.backend, sheet=args.sheet,
                   summary=Path(args.summary) if args.summary else None, force=args.force,
                   retries=args.retries, prune=args.prune, quiet=args.quiet, shard=shard)


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


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = sub.add_parser(
        "batch", help="render folders of material files or manifests to thumbnails",
        description="Render material files (TOML/JSON), folders of them (recursive) and "
                    "manifests to DIR, skipping outputs that are up to date. Each failure is a "
                    "line on stderr. Exit status 1 if any input failed (all others are still "
                    "rendered), 2 for a usage error or no material file found, 130 if "
                    "interrupted.")
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
    parser.add_argument("--shard", metavar="K/N",
                        help="render only shard K of N (1 ≤ K ≤ N), chosen by a hash of each "
                             "output name, so shards stay put as inputs come and go; "
                             "`opaline batch-merge` joins the shards' summaries")
    parser.add_argument("--prune", action="store_true",
                        help="remove images (and their .json sidecars) in DIR whose material "
                             "is gone; only files a batch wrote are touched")
    parser.add_argument("--report", nargs=2, metavar=("junit", "FILE"),
                        help="also write a JUnit XML report to FILE, one test case per "
                             "material (failures on the GitHub annotations too when "
                             "GITHUB_ACTIONS=true)")
    add_common(parser)
    parser.set_defaults(func=cmd_batch)
