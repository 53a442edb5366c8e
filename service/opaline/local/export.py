"""Exports without HTTP: a request's material as GLSL or as a .glb with its mesh, and a
.glb's material back as a material file. No GL context is needed for any of them.

    from opaline.local.export import export_material
    glsl = export_material({"preset": "cd-rom", "mu_f": 6}, "glsl")
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal, get_args

from opaline.gl.export_glsl import export_glsl
from opaline.local.api import RequestLike, as_request
from opaline.local.context import local_context
from opaline.output.gltf import export_preset_glb, import_glb
from opaline.pipeline.prepare import prepare

ExportKind = Literal["glsl", "glb"]


def export_material(request: RequestLike, kind: ExportKind) -> bytes:
    """GLSL source (UTF-8) or .glb bytes of the request's material (and, for .glb, mesh);
    the request is read as ``render``'s (a RequestError names a bad field)."""
    if kind not in get_args(ExportKind):  # "GLSL" or "fbx" silently gave a .glb
        raise ValueError(f"kind={kind!r}: expected one of {', '.join(get_args(ExportKind))}")
    prepared = prepare(as_request(request), local_context(cost_budget=None))
    preset, job = prepared.preset, prepared.job
    if kind == "glsl":
        return export_glsl(job.material, job.wavelengths).encode()
    return export_preset_glb(preset, job.material, job.wavelengths)


def import_material(path: Path | str, preset: str = "sphere") -> dict[str, Any]:
    """A material file's fields from a .glb: its material, drawn on its own mesh."""
    path = Path(path)
    fields = import_glb(path.read_bytes())
    return {"preset": preset, "mesh": str(path), **fields}


def material_file_text(fields: dict[str, Any]) -> str:
    return json.dumps(fields, indent=2) + "\n"
