"""Export a request's mesh and material as .glb in a worker: only workers build or load
meshes (a user's mesh file is parsed nowhere else)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from opaline.model.params import Material
from opaline.model.presets import Preset
from opaline.output.gltf import export_preset_glb
from opaline.workers.tasks import StopCheck

EXPORT_LABEL = "export-glb"


@dataclass(frozen=True)
class GlbTask:
    preset: Preset
    material: Material
    wavelengths: int
    label: str = EXPORT_LABEL

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        return export_preset_glb(self.preset, self.material, self.wavelengths)

    def units(self) -> tuple[str, float, int]:
        return EXPORT_LABEL, 0.0, 0
