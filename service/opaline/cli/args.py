"""Argument helpers shared by the sub-commands: --set, --size, --backend, the one-line error."""

from __future__ import annotations

import argparse

from pydantic import ValidationError

from opaline.model.params import RenderRequest, describe_errors, field_range
from opaline.settings import BACKENDS

TUPLE_FIELDS = {"albedo"}


class CliError(Exception):
    """A user error: printed as one line, exit status 2."""


def parameter_help() -> str:
    lines = ["parameters for --set NAME=VALUE (unset ones come from the preset):"]
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


def parse_sets(pairs: list[str]) -> dict[str, object]:
    values: dict[str, object] = {}
    for pair in pairs:
        name, sep, value = pair.partition("=")
        if not sep or not name:
            raise CliError(f"--set {pair!r}: expected NAME=VALUE, e.g. --set mu_f=8.5")
        values[name.strip()] = value.split(",") if name.strip() in TUPLE_FIELDS else value
    return values


def parse_size(text: str) -> tuple[int, int]:
    try:
        if "x" in text.lower():
            w, h = text.lower().split("x")
            return int(w), int(h)
        return int(text), int(text)
    except ValueError:
        raise CliError(f"--size {text!r}: expected WxH or N, e.g. --size 512x256") from None


def build_request(
    preset: str, sets: list[str], size: str | None, fmt: str | None, extra: dict
) -> RenderRequest:
    fields = parse_sets(sets)
    if size:
        fields["width"], fields["height"] = parse_size(size)
    if fmt:
        fields["format"] = fmt
    fields.update({k: v for k, v in extra.items() if v is not None})
    try:
        return RenderRequest(preset=preset, **fields)
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc))) from None


def add_common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--backend",
        choices=BACKENDS,
        default=None,
        help="headless GL backend (default: $OPALINE_GL_BACKEND or egl)",
    )
