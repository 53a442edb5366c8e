"""``opaline batch``: the command line of the batch renderer (``opaline.batch.run``)."""

from __future__ import annotations

import argparse
import signal
from pathlib import Path
from typing import Any, get_args

from pydantic import ValidationError

from opaline.batch.run import Options, _raise_interrupt, _signals, run_batch
from opaline.cli.args import CliError, add_common, parse_size
from opaline.model.params import ImageFormat, Quality, RenderRequest, describe_errors


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
