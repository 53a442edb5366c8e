"""``opaline schema``: the JSON Schema of a material file, for editors and validators."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from opaline.model.materials import material_schema
from opaline.output.files import write_atomic


def cmd_schema(args: Any) -> None:
    text = json.dumps(material_schema(), indent=2, ensure_ascii=False) + "\n"
    if args.output:
        write_atomic(Path(args.output), text.encode())
    else:
        print(text, end="")


def register(sub: Any) -> None:
    """``opaline schema``: the JSON Schema of a material file."""
    parser = sub.add_parser("schema", help="print the JSON Schema of a material file",
                            description="JSON Schema of Opaline's material file format "
                                        "(docs/materials.md), for editors and validators.")
    parser.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    parser.set_defaults(func=cmd_schema)
