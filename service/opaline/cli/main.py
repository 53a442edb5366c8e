"""The ``opaline`` command: render presets, MDF plots, list presets, report the context."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import get_args

from pydantic import ValidationError

from opaline.cli import batch, gallery, schema, serve
from opaline.cli.args import CliError, add_common, build_request, parameter_help, parse_sets
from opaline.model.params import (
    ImageFormat,
    Material,
    Quality,
    RenderFields,
    RenderRequest,
    describe_errors,
)
from opaline.model.presets import PresetError, UnknownPreset, all_presets
from opaline.model.request import CostError, resolve
from opaline.output.files import write_atomic


def cmd_render(args: argparse.Namespace) -> None:
    from opaline.local.pipeline import LocalRenderer

    request = build_request(
        args.preset,
        args.set,
        args.size,
        args.format,
        {"quality": args.quality, "transparent": args.transparent or None},
    )
    if args.verbose:
        print(chosen_setting(resolve(request)), file=sys.stderr)
    with LocalRenderer(args.backend) as renderer:
        data = renderer.render_bytes(request)
    write_atomic(Path(args.output), data)


def chosen_setting(job) -> str:
    """What a render will use; for quality=auto, also what it picked and why."""
    from opaline.model.auto import describe

    line = (f"quality {job.quality}: samples={job.samples} wavelengths={job.wavelengths} "
            f"aa={job.aa}")
    return f"{line} ({describe(job)})" if job.auto is not None else line


def cmd_mdf(args: argparse.Namespace) -> None:
    from opaline.local.pipeline import LocalRenderer

    fields = parse_sets(args.set)
    try:
        wavelengths = RenderFields(wavelengths=fields.pop("wavelengths", 0)).wavelengths or 0
        material = Material(**fields)
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc, RenderFields))) from None
    if not 16 <= args.size <= 2048:
        raise CliError(f"--size={args.size} is out of range: allowed [16 … 2048]")
    with LocalRenderer(args.backend) as renderer:
        data = renderer.mdf_bytes(material, args.size, args.format, wavelengths)
    write_atomic(Path(args.output), data)


def cmd_presets(args: argparse.Namespace) -> None:
    presets = all_presets()
    if args.json:
        print(json.dumps({n: p.model_dump(mode="json") for n, p in presets.items()}, indent=2))
        return
    for name, preset in presets.items():
        job = resolve(RenderRequest(preset=name), preset)
        m = job.material
        params = (
            f"mdf={m.mdf} mu_f={m.mu_f:g} alpha={m.alpha:g} beta={m.beta:g}"
            if m.mdf == "multipeak"
            else f"mdf={m.mdf} ex={m.ex:g} ey={m.ey:g}"
        )
        print(f"{name:<18} {preset.description}")
        print(f"{'':<18} {preset.figure}")
        print(
            f"{'':<18} defaults: {params} theta1={m.theta1:.4g} theta2={m.theta2:.4g} "
            f"kd={m.kd:g} ks={m.ks:g} f0={m.f0:g}"
        )


def cmd_info(args: argparse.Namespace) -> None:
    from opaline.gl.context import create_context

    gl = create_context(args.backend)
    try:
        info = gl.describe()
    finally:
        gl.release()
    for key, value in info.items():
        print(f"{key}: {value}")


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="opaline",
        description="Headless previews of iridescent materials (Kang, Lee, Cho 2014).",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    fmt = argparse.RawDescriptionHelpFormatter
    parameters = parameter_help()

    render = sub.add_parser(
        "render",
        help="render a preset to an image file",
        epilog=parameters,
        formatter_class=fmt,
    )
    render.add_argument("preset", help="preset name (see `opaline presets`)")
    render.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a parameter; repeatable (albedo takes R,G,B)",
    )
    render.add_argument(
        "--size", metavar="WxH", help="image size, each 16 … 2048 (default 256x256)"
    )
    render.add_argument(
        "--format", choices=get_args(ImageFormat), help="output format (default png)"
    )
    render.add_argument(
        "--quality", choices=get_args(Quality),
        help="quality tier (default standard); auto: the cheapest measured setting within "
        "--set max_flip=… / max_delta_e=… (FLIP 0.05 when neither is set)"
    )
    render.add_argument("--transparent", action="store_true", help="transparent PNG background")
    render.add_argument("-v", "--verbose", action="store_true",
                        help="print the samples, wavelengths and AA used (and what "
                        "quality=auto picked) on stderr")
    render.add_argument("-o", "--output", required=True, help="output file")
    add_common(render)
    render.set_defaults(func=cmd_render)

    mdf = sub.add_parser(
        "mdf",
        help="plot the MDF over the half-vector disc (Figs. 2, 3, 6, 7)",
        epilog=parameters,
        formatter_class=fmt,
    )
    mdf.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="material parameter; repeatable (mdf, ex, ey, mu_f, alpha, beta, theta1, "
        "theta2, wavelengths)",
    )
    mdf.add_argument("--size", type=int, default=256, help="plot size N (N×N), 16 … 2048")
    mdf.add_argument(
        "--format",
        choices=["png", "npy"],
        default="png",
        help="png (normalised, sRGB) or npy (linear D, float32)",
    )
    mdf.add_argument("-o", "--output", required=True, help="output file")
    add_common(mdf)
    mdf.set_defaults(func=cmd_mdf)

    presets = sub.add_parser("presets", help="list presets with their descriptions and defaults")
    presets.add_argument("--json", action="store_true", help="full preset data as JSON")
    presets.set_defaults(func=cmd_presets)

    info = sub.add_parser("info", help="report the GL backend and renderer Opaline gets")
    add_common(info)
    info.set_defaults(func=cmd_info)

    for module in (gallery, serve, batch, schema):
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = make_parser()
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except (CliError, PresetError, UnknownPreset, CostError) as exc:
        print(f"opaline {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"opaline {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # context or shader failures: one line, non-zero
        from opaline.gl.context import ContextError
        from opaline.gl.shaders import ShaderError

        if isinstance(exc, (ContextError, ShaderError)):
            print(f"opaline {args.command}: error: {exc}", file=sys.stderr)
            return 1
        raise
    return 0


if __name__ == "__main__":
    # Run the imported module's main, not this __main__ copy: sub-command modules raise
    # service.cli.CliError, which a second copy of the class would not catch.
    from opaline.cli.main import main as _main

    sys.exit(_main())
