"""``opaline render`` (a preset or a material file to an image) and ``opaline mdf`` (the MDF
plotted over the half-vector disc, the paper's Figs. 2, 3, 6, 7)."""

from __future__ import annotations

import argparse
import logging
import time
from typing import Any, get_args

from pydantic import ValidationError

from opaline.cli.args import (
    CliError,
    add_common,
    add_source,
    load_request,
    output_format,
    parameter_help,
    parse_size,
    plot_fields,
    plot_parameter_help,
    source_fields,
    write_output,
)
from opaline.model.params import ImageFormat, Material, Quality, RenderFields, describe_errors

log = logging.getLogger("opaline.cli")


def cmd_render(args: argparse.Namespace) -> None:
    from opaline.local.pipeline import LocalRenderer, prepare_locally

    fields: dict[str, Any] = source_fields(args)
    wanted = args.format or fields.pop("format", None)  # --set format=X is --format X
    if args.transparent:
        fields["transparent"] = True
    request = load_request(args.source, fields)
    # A format the material file names must fit the extension; the model's default need not.
    own = request.format if "format" in request.model_fields_set else None
    fmt = output_format(args.output, wanted, own)
    request = request.model_copy(update={"format": fmt})
    # Prepared (checked against the limits) before a GL context opens: a refusal costs none.
    prepared = prepare_locally(request)
    with LocalRenderer(args.backend) as renderer:
        job = prepared.job
        log.info("preset=%s %dx%d %s quality=%s samples=%d wavelengths=%d aa=%s cost=%d",
                 job.preset, job.width, job.height, job.format, job.quality, job.samples,
                 job.wavelengths, job.aa, job.cost)
        if job.tier.measured is not None:
            from opaline.model.auto import describe

            log.info("quality=auto picked: %s", describe(job))
        started = time.perf_counter()
        data = renderer.produce(prepared)
        log.info("rendered in %.3f s (%d bytes)", time.perf_counter() - started, len(data))
    write_output(args.output, data)
    log.info("wrote %s", "stdout" if args.output == "-" else args.output)


def cmd_mdf(args: argparse.Namespace) -> None:
    from opaline.local.pipeline import LocalRenderer

    fields = plot_fields(args.set)
    try:
        wavelengths = RenderFields(wavelengths=fields.pop("wavelengths", 0)).wavelengths or 0
        material = Material(**fields)
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc, RenderFields))) from None
    width, height = parse_size(args.size)
    if width != height:
        raise CliError(f"--size {args.size}: the MDF plot is square: give N or NxN")
    if not 16 <= width <= 2048:
        raise CliError(f"--size={width} is out of range: allowed [16 … 2048]")
    fmt = output_format(args.output, args.format, allowed=("png", "npy"))
    with LocalRenderer(args.backend) as renderer:
        log.info("mdf=%s %dx%d %s wavelengths=%d", material.mdf, width, width, fmt, wavelengths)
        started = time.perf_counter()
        data = renderer.mdf_bytes(material, width, fmt, wavelengths)
        log.info("plotted in %.3f s (%d bytes)", time.perf_counter() - started, len(data))
    write_output(args.output, data)


def add_output(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, metavar="FILE",
                        help="output file; its extension (.png, .npy) picks the format unless "
                             "--format is given; '-' writes to stdout (png by default)")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    fmt = argparse.RawDescriptionHelpFormatter
    render = sub.add_parser("render", help="render a preset or a material file to an image",
                            epilog=parameter_help(), formatter_class=fmt)
    add_source(render, "draw this mesh (glTF/GLB, OBJ, PLY, STL) with the preset's lights "
                       "and material; the camera frames it")
    render.add_argument("--size", metavar="WxH",
                        help="image size WxH or N (N×N), each 16 … 2048 (default 256x256)")
    render.add_argument("--format", choices=get_args(ImageFormat),
                        help="output format (default: from the -o extension; png16 needs "
                             "--format png16 with .png)")
    render.add_argument("--quality", choices=get_args(Quality),
                        help="quality tier (default standard); auto: the cheapest measured "
                             "setting within --set max_flip=… / max_delta_e=… (FLIP 0.05 when "
                             "neither is set)")
    render.add_argument("--transparent", action="store_true",
                        help="transparent PNG background")
    add_output(render)
    add_common(render)
    render.set_defaults(func=cmd_render)

    mdf = sub.add_parser("mdf", help="plot the MDF over the half-vector disc (Figs. 2, 3, 6, 7)",
                         epilog=plot_parameter_help(), formatter_class=fmt)
    mdf.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="plot parameter; repeatable (listed below)")
    mdf.add_argument("--size", default="256", metavar="N",
                     help="plot size N (or NxN: the plot is square), 16 … 2048 (default 256)")
    mdf.add_argument("--format", choices=["png", "npy"],
                     help="png (normalised, sRGB) or npy (linear D, float32); default: from "
                          "the -o extension")
    add_output(mdf)
    add_common(mdf)
    mdf.set_defaults(func=cmd_mdf)
