"""Exports without HTTP: a request's material as GLSL or as a .glb with its mesh, and a
.glb's material back as a material file. No GL context is needed for any of them.

    from opaline.local.export import export_material
    glsl = export_material({"preset": "cd-rom", "mu_f": 6}, "glsl")
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

from opaline.gl.export_glsl import export_glsl
from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.output.gltf import export_preset_glb, import_glb
from opaline.pipeline.prepare import prepare

ExportKind = Literal["glsl", "glb"]


def export_material(request: RenderRequest | Mapping[str, Any], kind: ExportKind) -> bytes:
    """GLSL source (UTF-8) or .glb bytes of the request's material (and, for .glb, mesh)."""
    if not isinstance(request, RenderRequest):
        request = RenderRequest.model_validate(dict(request))
    prepared = prepare(request, local_context(cost_budget=None))
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
