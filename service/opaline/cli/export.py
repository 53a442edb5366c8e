"""``opaline export`` (a material as GLSL or .glb) and ``opaline import`` (a .glb's material
as a material file that renders it on the .glb's own mesh)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import TYPE_CHECKING

from opaline.cli.args import (
    STDOUT,
    CliError,
    add_common,
    add_source,
    load_request,
    source_fields,
    write_output,
)

if TYPE_CHECKING:  # the command imports local.export only when it runs
    from opaline.local.export import ExportKind

log = logging.getLogger("opaline.cli")
KINDS: dict[str, ExportKind] = {".glsl": "glsl", ".frag": "glsl", ".glb": "glb"}


def cmd_export(args: argparse.Namespace) -> None:
    from opaline.local.export import export_material

    request = load_request(args.source, source_fields(args))
    kind = KINDS.get(Path(args.output).suffix.lower())
    if kind is None:
        raise CliError(f"-o {args.output}: the name must end in .glsl, .frag or .glb")
    data = export_material(request, kind)
    write_output(args.output, data)
    log.info("wrote %s (%d bytes)", args.output, len(data))


def cmd_import(args: argparse.Namespace) -> None:
    from opaline.local.export import import_material, material_file_text
    from opaline.model.presets import UnknownPreset, get_preset

    out = Path(args.output)
    if args.output != STDOUT and out.suffix.lower() != ".json":  # a .toml failed to render
        raise CliError(f"-o {args.output}: import writes a JSON material file: name it .json")
    try:  # a preset that is not one wrote a file that no render could read
        get_preset(args.preset)
    except UnknownPreset as exc:
        raise CliError(f"--preset {args.preset}: {exc}") from None
    fields = import_material(args.source, args.preset)
    # The mesh path is written relative to the material file, as load_material reads it.
    try:
        fields["mesh"] = str(Path(fields["mesh"]).resolve().relative_to(out.resolve().parent))
    except ValueError:
        fields["mesh"] = str(Path(fields["mesh"]).resolve())
    write_output(args.output, material_file_text(fields).encode())


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    export = sub.add_parser("export", help="a material as a GLSL function (.glsl) or as glTF "
                                           "with its mesh (.glb)")
    add_source(export, "export this mesh instead of the preset's")
    export.add_argument("-o", "--output", required=True, metavar="FILE",
                        help="FILE.glsl (or .frag) or FILE.glb")
    add_common(export)
    export.set_defaults(func=cmd_export)
    imp = sub.add_parser("import", help="a .glb exported by Opaline, or any .glb with "
                                        "KHR_materials_iridescence → a material file (JSON)")
    imp.add_argument("source", metavar="FILE.glb")
    imp.add_argument("--preset", default="sphere", help="preset for lights and background")
    imp.add_argument("-o", "--output", required=True, metavar="FILE.json")
    add_common(imp)
    imp.set_defaults(func=cmd_import)
