"""``opaline turntable``: a preset, a material file or a mesh, turned once around, as an
animated WebP, a GIF or an MP4; progress on stderr, one line per frame."""

from __future__ import annotations

import argparse
import logging
import time
from typing import TYPE_CHECKING, get_args

from pydantic import ValidationError

from opaline.cli.args import (
    CliError,
    add_common,
    add_source,
    load_request,
    source_fields,
    write_output,
)
from opaline.model.params import Quality, describe_errors

if TYPE_CHECKING:
    from opaline.model.turntable import AnimationFormat

log = logging.getLogger("opaline.cli")
SUFFIXES: dict[str, AnimationFormat] = {".webp": "webp", ".gif": "gif", ".mp4": "mp4"}


def cmd_turntable(args: argparse.Namespace) -> None:
    from opaline.local.pipeline import LocalRenderer
    from opaline.local.turntable import prepare_turntable, turntable_bytes
    from opaline.model.turntable import TurntableRequest

    base = load_request(args.source, source_fields(args))
    suffix = next((s for s in SUFFIXES if args.output.lower().endswith(s)), None)
    if args.format and suffix and SUFFIXES[suffix] != args.format:
        raise CliError(f"--format {args.format} does not match -o {args.output}: "
                       f"{args.format} files end in .{args.format}")
    fmt = args.format or (SUFFIXES[suffix] if suffix else None)
    if fmt is None:
        raise CliError(f"-o {args.output}: give --format webp|gif|mp4 or a .webp/.gif/.mp4 name")
    try:
        request = TurntableRequest(**base.model_dump(exclude_none=True), frames=args.frames,
                                   fps=args.fps, animation=fmt)
    except ValidationError as exc:  # frames, fps: named with their range, as the API does
        raise CliError("; ".join(describe_errors(exc, TurntableRequest))) from None
    prepared = prepare_turntable(request)  # checked before a GL context opens
    started = time.perf_counter()

    def progress(done: int, total: int) -> None:
        log.info("frame %d/%d (%.1f s)", done, total, time.perf_counter() - started)

    with LocalRenderer(args.backend) as local:
        data = turntable_bytes(local, request, progress, prepared)
    log.info("%d frames in %.2f s (%d bytes)", request.frames, time.perf_counter() - started,
             len(data))
    write_output(args.output, data)


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = sub.add_parser("turntable", help="render the object from every side: an animated "
                                              "WebP, GIF or MP4")
    add_source(parser, "draw this mesh file instead")
    parser.add_argument("--frames", type=int, default=36, help="frames in one turn (default 36)")
    parser.add_argument("--fps", type=int, default=24, help="frames per second (default 24)")
    parser.add_argument("--size", metavar="WxH", help="frame size (default 256x256)")
    parser.add_argument("--quality", choices=list(get_args(Quality)), help="quality tier")
    parser.add_argument("--format", choices=["webp", "gif", "mp4"],
                        help="default: from the -o extension")
    parser.add_argument("-o", "--output", required=True, metavar="FILE", help="output file")
    add_common(parser)
    parser.set_defaults(func=cmd_turntable)
