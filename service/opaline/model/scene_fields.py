"""Request fields that change the scene rather than the material: the user's mesh, its
tangent field, and the camera's orbit around the target.

``RenderFields`` inherits them, so the CLI's ``--set``, material files, the
Python API and both HTTP forms accept them with the same ranges. The mesh
fields turn the preset into a mesh preset (``opaline.model.meshes``) and are not part
of the ``Job``; the orbit fields are, because they change the image but not
what is uploaded to the GPU (a turntable reuses one upload for every frame).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from opaline.model.tiers import TIERS
from opaline.scene.environments import BUILTIN, MESH_ENVIRONMENT, NO_ENVIRONMENT

TangentField = Literal["auto", "uv", "concentric", "projected"]
Finite3 = tuple[Annotated[float, Field(ge=-1e6, le=1e6)], Annotated[float, Field(ge=-1e6, le=1e6)],
                Annotated[float, Field(ge=-1e6, le=1e6)]]
MESH_FIELDS = ("mesh", "tangent_field", "tangent_axis", "mesh_up")
ORBIT_FIELDS = ("camera_azimuth", "camera_elevation", "camera_distance")
BUILT_IN = ", ".join(f"'{name}'" for name in BUILTIN)


def _per_tier(setting: str) -> str:
    """A tier setting's values as the help states them: "draft 2, standard 6, …"."""
    return ", ".join(f"{name} {getattr(tier, setting)}" for name, tier in TIERS.items())


class SceneFields(BaseModel):
    # As params.STRICT (params imports this module, so it cannot be imported from there).
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

    mesh: Annotated[str, Field(min_length=1, max_length=1024)] | None = Field(
        None, description="The user's own mesh instead of the preset's: a file path (CLI, "
                          "Python, material files; glTF/GLB, OBJ, PLY, STL) or, over HTTP, "
                          "the id POST /v1/meshes answered (or a file of the meshes folder).")
    tangent_field: TangentField | None = Field(
        None, description="Tangents of a mesh: 'uv' (from its UVs), 'concentric' (circles about "
                          "tangent_axis), 'projected' (tangent_axis projected on the surface); "
                          "'auto' (default): 'uv' where the mesh has UVs, else 'concentric'.")
    tangent_axis: Finite3 | None = Field(
        None, description="Axis of the concentric field, or direction of the projected one "
                          "(default 0,1,0; an axis of length under 1e-9, which has no "
                          "direction, is the default).")

    mesh_up: Literal["y", "z"] | None = Field(
        None, description="The mesh file's up axis: 'y' (default; glTF's) or 'z' (many scans "
                          "and CAD exports: OBJ, PLY and STL cannot say which): a Z-up file is "
                          "turned so that its +z is up, before its tangents and maps.")

    @field_validator("mesh_up")
    @classmethod
    def _up(cls, up: str | None) -> str | None:
        return None if up == "y" else up  # the default, one URL and key whether named or not

    @field_validator("tangent_axis")
    @classmethod
    def _direction(cls, axis: Finite3 | None) -> Finite3 | None:
        # Every schema-valid value is accepted (the schema cannot state a length): one with
        # no direction means the default, decided here, before a worker builds the field.
        # Only its direction counts, so it is kept as a unit vector and the default's
        # direction is the default: 0,2,0 and 0,1,0 are one image, with one URL and key.
        if axis is None:
            return None
        length = math.sqrt(sum(c * c for c in axis))
        if length < 1e-9:
            return None
        unit = (axis[0] / length, axis[1] / length, axis[2] / length)
        return None if unit == (0.0, 1.0, 0.0) else unit
    camera_azimuth: Annotated[float, Field(ge=-360.0, le=360.0)] | None = Field(
        None, description="Camera azimuth in degrees around the target's up axis "
                          "(0: +x, 90: +z), -360 … 360 (default: the preset's view).")
    camera_elevation: Annotated[float, Field(ge=-89.0, le=89.0)] | None = Field(
        None, description="Camera elevation in degrees above the target's horizon, -89 … 89.")
    camera_distance: Annotated[float, Field(ge=0.2, le=10.0)] | None = Field(
        None, description="Camera distance as a multiple of the preset's (or, for a mesh, of "
                          "the distance that frames its bounds), 0.2 … 10 (default 1).")

    environment: Annotated[str, Field(min_length=1, max_length=255)] | None = Field(
        None, description="Light the scene with an environment instead of the preset's lights: "
                          f"{BUILT_IN}, or an .hdr/.exr file: by its name in the "
                          "environments folder, or (CLI, Python, material files: relative "
                          "to the file) by its path; "
                          f"'{NO_ENVIRONMENT}' keeps the preset's lights. Default: the "
                          "preset's (none on most; studio on soap-bubble, the films on "
                          f"metals, the stacks and coated-paint), '{MESH_ENVIRONMENT}' on a "
                          "user's mesh.",
        examples=[*BUILTIN, NO_ENVIRONMENT])
    environment_rotation: Annotated[float, Field(ge=-360.0, le=360.0)] | None = Field(
        None, description="Turns the environment about the up axis, degrees (default 0).")
    environment_intensity: Annotated[float, Field(ge=0.0, le=1000.0)] | None = Field(
        None, description="Multiplies the environment's radiance, 0 … 1000 (default 1).")
    environment_lights: Annotated[int, Field(ge=1, le=256)] | None = Field(
        None, description="K: light the scene with the environment as K directional lights "
                          "by median cut instead of reading the map, 1 … 256 (the RGB paths, "
                          "wavelengths=0, of a grating and of the multi-peak lobe always do, "
                          "by default with the tier's K: draft 8, standard 16, high 32, "
                          "reference 64).")
    environment_samples: Annotated[int, Field(ge=1, le=4096)] | None = Field(
        None, description="Directions drawn from the material's lobe per pixel to read the "
                          "environment map, 1 … 4096 (default: the tier's: "
                          f"{_per_tier('environment_samples')}; for the rotation source's "
                          "Ashikhmin-Shirley lobes "
                          f"{_per_tier('environment_samples_rotation')}; for a grating, the "
                          "reads along the curve its orders leave by, "
                          f"{_per_tier('environment_samples_grating')}). The spectral "
                          "multi-peak lobe reads its envelope from the map's irradiance and "
                          "takes these only for its bands: at most one a pass per 4 "
                          "wavelengths, and none where `samples` (not this field) are too few "
                          "to resolve them (the presets' bands need 4 or more). Ignored where "
                          "the environment becomes lights (environment_lights set, or "
                          "wavelengths=0 with a grating or the multi-peak lobe).")
    environment_background: bool | None = Field(
        None, description="Show the environment behind the object instead of the preset's "
                          "background (default false).")
    environment_blur: Annotated[float, Field(ge=0.0, le=1.0)] | None = Field(
        None, description="Blurs the environment shown behind the object, 0 … 1: 0 (default) "
                          "sharp, 1 a soft wash about 30° across; the lighting is unchanged.")
