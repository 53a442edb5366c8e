"""A request's mesh fields applied to a preset: the preset's lights, background and
defaults drawing the user's mesh (geometry kind ``file``, loaded in the worker by
``opaline.scene.meshfile``), the camera framed on its bounds by the renderer."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from opaline.digests import known_file_digest
from opaline.model.presets import Generator, Preset
from opaline.model.scene_fields import SceneFields
from opaline.scene.environments import MESH_ENVIRONMENT, expand_user
from opaline.scene.gltf_film import film_texture_names

MESH_KIND = "file"
# The camera a mesh gets (azimuth, elevation in degrees): three-quarter view from above.
MESH_VIEW = (60.0, 20.0)


def mesh_preset(base: Preset, path: Path, digest: str, request: SceneFields, max_triangles: int) -> Preset:
    """``base`` drawing the mesh at ``path``: its background, defaults and maps, lit by
    ``MESH_ENVIRONMENT`` unless the preset names an environment, the camera framed on the
    mesh by the renderer (the maps projected in object space where the mesh has no UVs, or
    where the preset asks: ``opaline.model.projection``). A .glb carrying a KHR thickness
    texture draws its film with it instead of the preset's field, and one with a factor
    texture weighs its film by it texel by texel."""
    # The generator's arguments (scene.meshfile.mesh_file's), of their several types.
    args: dict[str, Any] = {"kind": MESH_KIND, "path": str(path), "digest": digest,
                            "tangent_field": request.tangent_field or _default_field(base),
                            "tangent_axis": list(request.tangent_axis or (0.0, 1.0, 0.0)),
                            "max_triangles": max_triangles}
    if request.mesh_up == "z":  # only then: a Y-up mesh keeps the scene key it had
        args["up"] = "z"
    defaults = base.defaults.model_copy(
        update={"environment": base.defaults.environment or MESH_ENVIRONMENT})
    update: dict[str, Any] = {"name": f"mesh-{digest[:12]}", "geometry": Generator(**args),
                              "defaults": defaults, "tangents": "uv",
                              "rotation_deg": (0.0, 0.0, 0.0)}
    names = film_texture_names(path)
    film: dict[str, Any] = {"path": str(path), "digest": digest}
    if "iridescenceThicknessTexture" in names:  # a .glb's own film, in its own UVs
        update.update(thickness_map=Generator(kind="glb", **film), mesh_projection="auto")
    if "iridescenceTexture" in names:  # and its weight per texel
        update.update(weight_map=Generator(kind="glb-factor", **film), mesh_projection="auto")
    return base.model_copy(update=update)


def _default_field(base: Preset) -> str:
    """A preset drawn with concentric tangents (the CD's tracks) gives a mesh concentric
    ones about ``tangent_axis``, UVs or not; the others follow the mesh's UVs."""
    return "concentric" if base.tangents == "concentric" else "auto"


def is_mesh(preset: Preset) -> bool:
    return preset.geometry.kind == MESH_KIND


class MeshFileMissing(ValueError):
    """A request names a mesh file that does not exist (CLI, Python API, material files)."""


def file_mesh_preset(base: Preset, request: SceneFields, max_triangles: int) -> Preset:
    """``base`` drawing the mesh file ``request.mesh`` (a path on this machine)."""
    assert request.mesh is not None
    path = expand_user(Path(request.mesh))
    if not path.is_file():
        raise MeshFileMissing(f"mesh={request.mesh!r}: no such file")
    # Hashed again only when the file changes, as the meshes folder's and environment
    # files are: each render of the Python API's or a batch's mesh read it whole.
    path = path.resolve()
    return mesh_preset(base, path, known_file_digest(path), request, max_triangles)
