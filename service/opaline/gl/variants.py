"""Which variant of the surface program a job needs: one define per feature in use, so
features that are off are not compiled in (no uniform branches on them)."""

from __future__ import annotations

from opaline.gl import heightfield, physical, uniforms
from opaline.model.presets import Preset
from opaline.model.request import Job


def surface_defines(job: Job, preset: Preset) -> dict[str, int | bool]:
    """The surface program's feature defines: only what this scene and material use."""
    defines = uniforms.material_defines(job.material, job.wavelengths, job.aa)
    defines["NORMAL_MAP"] = preset.normal_map is not None
    defines["TANGENT_CONCENTRIC"] = preset.tangents == "concentric"
    defines["LIGHT_COUNT"] = len(preset.lights)
    defines.update(heightfield.defines(preset))
    if physical.uses_thickness_map(job.material, preset):
        defines["THICKNESS_MAP"] = True
    if physical.uses_transmission(job.material, preset):
        defines["TRANSMISSION"] = True
    return defines
