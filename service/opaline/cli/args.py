"""Argument helpers shared by the sub-commands: --set, --size, --backend, the output file
(its format from the extension, ``-`` for stdout) and the one-line error."""

from __future__ import annotations

import argparse
import difflib
import sys
from pathlib import Path
from typing import Any, get_args

from pydantic import ValidationError

from opaline.model.material import MDF_PLOT_FIELDS
from opaline.model.material_file import MaterialError, load_material
from opaline.model.params import (
    ImageFormat,
    Material,
    MaterialFields,
    RenderRequest,
    describe_errors,
    field_range,
    tuple_fields,
)
from opaline.output.encode import EXTENSIONS
from opaline.output.files import write_atomic
from opaline.settings import BACKENDS

TUPLE_FIELDS = tuple_fields(RenderRequest)  # their --set value is split at commas
MATERIAL_SUFFIXES = (".toml", ".json")
# What an extension may hold: the first is what the extension alone means.
FORMATS_BY_SUFFIX = {".png": ("png", "png16"), ".npy": ("npy",), ".webp": ("webp", "webp-lossless"),
                     ".avif": ("avif",), ".jpg": ("jpeg",), ".jpeg": ("jpeg",)}
STDOUT = "-"


class CliError(Exception):
    """A user error: printed as one line, exit status ``status`` (2: usage)."""

    status = 2


class OutputError(CliError):
    """The output cannot be written (permissions, no such folder, ...): exit status 1."""

    status = 1


def parameter_help() -> str:
    lines = ["parameters for --set NAME=VALUE (unset ones come from the preset or file):"]
    column = max(16, *(len(name) + 1 for name in RenderRequest.model_fields))
    for name, info in RenderRequest.model_fields.items():
        if name == "preset":
            continue
        desc = info.description or ""
        allowed = field_range(RenderRequest, name)
        # Descriptions state their range in words; add the bounds where one does not.
        if allowed and "…" not in desc:
            desc += f" Range {allowed}."
        lines.append(f"  {name:<{column}} {desc}")
    return "\n".join(lines)


def suggest(name: str, known: list[str] | tuple[str, ...]) -> str:
    """", did you mean X?" for the nearest known name, or nothing when none is close."""
    near = difflib.get_close_matches(name, known, n=1)
    return f", did you mean {near[0]}?" if near else ""


def parse_sets(pairs: list[str]) -> dict[str, Any]:
    values: dict[str, Any] = {}
    for pair in pairs:
        name, sep, value = pair.partition("=")
        if not sep or not name:
            raise CliError(f"--set {pair!r}: expected NAME=VALUE, e.g. --set mu_f=8.5")
        name = name.strip()
        if name in values:  # as a query parameter or a JSON key given twice is refused
            raise CliError(f"--set {name}: given more than once; give each parameter once")
        values[name] = value.split(",") if name in TUPLE_FIELDS else value
    return values


def parse_size(text: str) -> tuple[int, int]:
    try:
        if "x" in text.lower():
            w, h = text.lower().split("x")
            return int(w), int(h)
        return int(text), int(text)
    except ValueError:
        raise CliError(f"--size {text!r}: expected WxH or N, e.g. --size 512x256") from None


def load_request(source: str, fields: dict[str, Any]) -> RenderRequest:
    """A preset name, or an existing material file (.toml/.json), with ``fields`` on top."""
    if source.lower().endswith(MATERIAL_SUFFIXES):
        if not Path(source).is_file():
            raise CliError(f"{source}: no such material file")
        try:
            return load_material(source, fields)
        except MaterialError as exc:
            raise CliError(str(exc)) from None
    if "preset" in fields and fields["preset"] != source:
        raise CliError(f"--set preset={fields['preset']}: the preset is the command's first "
                       f"argument, here {source!r}; name {fields['preset']!r} there instead")
    try:
        return RenderRequest(**{**fields, "preset": source})
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc))) from None


def output_format(output: str, wanted: str | None, own: str | None = None,
                  allowed: tuple[str, ...] = get_args(ImageFormat)) -> str:
    """The format to write ``output`` in: ``--format`` if given, else the format a material
    file names (``own``), else what the extension means; png for stdout. A format the
    extension cannot hold, or one this command cannot write, is an error."""
    if wanted is not None and wanted not in allowed:
        raise CliError(f"format={wanted!r}: expected one of {', '.join(allowed)}")
    fits = FORMATS_BY_SUFFIX.get(Path(output).suffix.lower()) if output != STDOUT else None
    if fits is not None and not set(fits) & set(allowed):
        raise CliError(f"-o {output}: this command writes {' or '.join(allowed)}, not "
                       f"{fits[0]}: use {' or '.join(EXTENSIONS[f] for f in allowed)}")
    for given, said in ((wanted, "--format"), (own, "format")):
        if given and fits and given not in fits:
            raise CliError(f"{said} {given} does not match -o {output}: {given} files end "
                           f"in {EXTENSIONS[given]}")
        if given:
            return given
    if output == STDOUT:
        return "png"
    if not fits:
        raise CliError(f"-o {output}: cannot tell the format from the extension: "
                       "use .png, .npy, .webp, .avif or .jpg, or give --format")
    return next(f for f in fits if f in allowed)


def write_output(output: str, data: bytes) -> None:
    """Write the image to ``output`` whole (or not at all), or to stdout for ``-``."""
    if output == STDOUT:
        if sys.stdout.isatty():
            raise CliError("-o -: refusing to write image data to a terminal; pipe it or "
                           "redirect it to a file")
        sys.stdout.flush()
        sys.stdout.buffer.write(data)
        sys.stdout.buffer.flush()
        return
    try:
        write_atomic(Path(output), data)
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            raise
        raise OutputError(f"cannot write {output}: {exc.strerror or exc}") from None


PLOT_FIELDS = (*MDF_PLOT_FIELDS, "wavelengths")
WAVELENGTHS_HELP = ("0 = the paper's RGB rotations (default), else 3 … 128 wavelengths "
                    "integrated with CIE 1931.")


def plot_parameter_help() -> str:
    """The MDF plot's own parameter list: only what changes the plot, with its default."""
    lines = ["plot parameters for --set NAME=VALUE (unset ones take the default shown):"]
    for name in PLOT_FIELDS:
        if name == "wavelengths":
            lines.append(f"  {name:<12} {WAVELENGTHS_HELP}")
            continue
        desc = MaterialFields.model_fields[name].description or ""
        lines.append(f"  {name:<12} {desc} Default {Material.model_fields[name].default}.")
    return "\n".join(lines)


def plot_fields(pairs: list[str]) -> dict[str, Any]:
    """--set for the MDF plot: a field that does not change the plot is refused, not ignored."""
    fields = parse_sets(pairs)
    problems = []
    for name in fields:
        if name in PLOT_FIELDS:
            continue
        if name in RenderRequest.model_fields:
            problems.append(f"--set {name}: does not affect the MDF plot")
        else:
            problems.append(f"--set {name}: unknown field{suggest(name, PLOT_FIELDS)}")
    if problems:
        raise CliError("; ".join(problems) + f" (plot parameters: {', '.join(PLOT_FIELDS)})")
    return fields


def add_source(parser: argparse.ArgumentParser, mesh_help: str) -> None:
    """What render, turntable and export draw: a preset or material file, ``--set``
    overrides, and ``--mesh``."""
    parser.add_argument("source", metavar="PRESET|FILE",
                        help="preset name (see `opaline presets`) or material file "
                             "(.toml/.json, see `opaline schema`)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a parameter; repeatable (albedo takes R,G,B)")
    parser.add_argument("--mesh", metavar="FILE", help=mesh_help)


def source_fields(args: argparse.Namespace) -> dict[str, Any]:
    """``--set``, ``--mesh`` and, where the command has them, ``--size`` and ``--quality``
    as request fields (the request model validates them)."""
    fields = parse_sets(args.set)
    options: dict[str, Any] = {}
    if getattr(args, "size", None):
        options["width"], options["height"] = parse_size(args.size)
    if getattr(args, "quality", None):
        options["quality"] = args.quality
    if args.mesh:
        options["mesh"] = args.mesh
    for name, value in options.items():  # one of the two silently won
        if name in fields and fields[name] != value:
            option = {"width": "--size", "height": "--size"}.get(name, f"--{name}")
            raise CliError(f"{option} and --set {name}={fields[name]} disagree: give one")
    return {**fields, **options}


def add_common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--backend",
        choices=BACKENDS,
        default=None,
        help="headless GL backend (default: $OPALINE_GL_BACKEND or egl)",
    )
