"""Exports run in a worker: the mesh and material as .glb (only workers build or load
meshes: a user's mesh file is parsed nowhere else), and the material as GLSL (its
uniforms are written by ``opaline.gl``, which loads moderngl: the HTTP process never
imports GL)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from opaline.model.params import Material
from opaline.model.presets import Preset
from opaline.output.gltf import export_preset_glb
from opaline.workers.tasks import StopCheck

EXPORT_LABEL = "export-glb"
GLSL_LABEL = "export-glsl"


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


@dataclass(frozen=True)
class GlslTask:
    material: Material
    wavelengths: int
    label: str = GLSL_LABEL

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        # imported here: this module is imported by the HTTP process, which must not load GL
        from opaline.gl.export_glsl import export_glsl

        return export_glsl(self.material, self.wavelengths).encode()

    def units(self) -> tuple[str, float, int]:
        return GLSL_LABEL, 0.0, 0
