"""A tuned material leaves Opaline as glTF 2.0 binary (.glb), and comes back.

The .glb holds the mesh (positions, normals, tangents with w = +1 because
Opaline's frame is ``(t, cross(n, t), n)``, UVs with glTF's v down, uint32
indices) and one material: a metallic-roughness approximation for viewers
that know nothing else, and in ``extras.opaline`` the paper's parameters
exactly, which ``import_glb`` reads back into request fields. The paper's
multi-peak and Ashikhmin-Shirley MDFs have no glTF extension; thin-film
materials are also written as KHR_materials_iridescence (gltf_iridescence.py),
and a .glb with that extension and no extras imports as a thin-film material.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pygltflib as gl

from opaline import __version__
from opaline.model.coat import roughness_from_exponent
from opaline.model.meshes import is_mesh
from opaline.model.params import MATERIAL_FIELDS, Material
from opaline.model.presets import Preset, build_assets, build_thickness
from opaline.output.gltf_coat import coat_extensions
from opaline.output.gltf_iridescence import (
    add_film_texture,
    base_colour_and_metallic,
    field_png,
    is_thin_film,
    thin_film_extensions,
    thin_film_fields,
)
from opaline.scene.gltf_film import (
    IRIDESCENCE,
    FilmTextures,
    load_document,
    read_film_textures,
    texture_names,
)
from opaline.scene.mesh import Mesh

EXTRAS_KEY = "opaline"


def _roughness(material: Material) -> float:
    """A rough stand-in for viewers: the MDF's width as GGX-like roughness (no exact map;
    an A-S lobe's by its wider exponent's equivalent GGX width)."""
    if material.mdf == "ashikhmin" or material.iridescence != "rotation":  # A-S lobe
        return roughness_from_exponent(min(material.ex, material.ey))
    return float(np.clip(0.15 * (material.alpha + material.beta) / 2.0, 0.05, 1.0))


def export_glb(mesh: Mesh, material: Material, wavelengths: int = 0, name: str = "opaline",
               tangents: dict[str, Any] | None = None,
               textures: FilmTextures | None = None) -> bytes:
    """``tangents``: the request fields (``tangent_field``, ``tangent_axis``) that give the
    mesh's tangents back when it is imported (the CD's are concentric, not its UVs').
    ``textures``: the [0, 1] film-thickness field (the preset's, or a user's .glb's) and
    a .glb's own factor texture, written as KHR's textures when the material is a thin
    film."""
    arrays = [
        (mesh.positions, gl.VEC3, gl.FLOAT, gl.ARRAY_BUFFER),
        (mesh.normals, gl.VEC3, gl.FLOAT, gl.ARRAY_BUFFER),
        (np.c_[mesh.tangents, np.ones(len(mesh.tangents), np.float32)], gl.VEC4, gl.FLOAT,
         gl.ARRAY_BUFFER),
        (np.c_[mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]].astype(np.float32), gl.VEC2, gl.FLOAT,
         gl.ARRAY_BUFFER),
        (mesh.indices.reshape(-1), gl.SCALAR, gl.UNSIGNED_INT, gl.ELEMENT_ARRAY_BUFFER),
    ]
    blob, views, accessors = b"", [], []
    for index, (data, kind, component, target) in enumerate(arrays):
        raw = np.ascontiguousarray(data).tobytes()
        views.append(gl.BufferView(buffer=0, byteOffset=len(blob), byteLength=len(raw),
                                   target=target))
        accessor = gl.Accessor(bufferView=index, componentType=component, type=kind,
                               count=len(data))
        if index == 0:  # glTF requires bounds on positions
            accessor.min = mesh.positions.min(axis=0).tolist()
            accessor.max = mesh.positions.max(axis=0).tolist()
        accessors.append(accessor)
        blob += raw + b"\0" * (-len(raw) % 4)
    film = is_thin_film(material)
    image_views: dict[str, int] = {}
    for key, field in (textures.by_key() if film and textures else {}).items():
        raw = field_png(field)
        image_views[key] = len(views)
        views.append(gl.BufferView(buffer=0, byteOffset=len(blob), byteLength=len(raw)))
        blob += raw + b"\0" * (-len(raw) % 4)
    params = material.model_dump(mode="json")
    colour, metallic = list(material.albedo), material.ks / max(material.ks + material.kd, 1e-9)
    if film:  # the base under the film: a dielectric (KHR_materials_ior) or a metal
        colour, metallic = base_colour_and_metallic(material)
    gltf_material = gl.Material(
        name=name, doubleSided=True,
        pbrMetallicRoughness=gl.PbrMetallicRoughness(
            baseColorFactor=[*colour, 1.0],
            metallicFactor=float(metallic),
            roughnessFactor=_roughness(material)),
        extras={EXTRAS_KEY: {"model": "Kang, Lee, Cho 2014 multi-peak anisotropic microfacet",
                             "version": __version__, "material": params,
                             "wavelengths": wavelengths, "tangents": tangents or {}}})
    primitive = gl.Primitive(attributes=gl.Attributes(POSITION=0, NORMAL=1, TANGENT=2,
                                                      TEXCOORD_0=3), indices=4, material=0)
    document = gl.GLTF2(
        asset=gl.Asset(generator=f"Opaline {__version__}", version="2.0"),
        scene=0, scenes=[gl.Scene(nodes=[0])], nodes=[gl.Node(mesh=0, name=name)],
        meshes=[gl.Mesh(name=name, primitives=[primitive])], materials=[gltf_material],
        accessors=accessors, bufferViews=views, buffers=[gl.Buffer(byteLength=len(blob))])
    extensions = coat_extensions(material)
    if film:
        indices = {key: add_film_texture(document, view) for key, view in image_views.items()}
        extensions.update(thin_film_extensions(material, indices))
    if extensions:
        gltf_material.extensions = extensions
        document.extensionsUsed = sorted(extensions)
    document.set_binary_blob(blob)
    return b"".join(document.save_to_bytes())


def tangent_fields(preset: Preset) -> dict[str, Any]:
    """What makes the mesh's tangents again on import: the CD's concentric field, a file
    mesh's own choice; UV-following tangents come back from the UVs by themselves."""
    if is_mesh(preset):
        args = preset.geometry.args
        return {"tangent_field": args["tangent_field"], "tangent_axis": args["tangent_axis"]}
    if preset.tangents == "concentric":  # about the object's y axis, as the shader's field
        return {"tangent_field": "concentric", "tangent_axis": [0.0, 1.0, 0.0]}
    return {}


def export_preset_glb(preset: Preset, material: Material, wavelengths: int = 0) -> bytes:
    """The preset's mesh, tangent fields and (for a thin film) thickness field as .glb; a
    user's .glb gives back the factor texture it came with too."""
    mesh, _ = build_assets(preset)
    textures = None
    if is_thin_film(material):
        factor = None
        if is_mesh(preset):
            data = Path(preset.geometry.args["path"]).read_bytes()
            if "iridescenceTexture" in texture_names(data):
                factor = read_film_textures(data, ("iridescenceTexture",)).factor
        textures = FilmTextures(build_thickness(preset), factor)
    return export_glb(mesh, material, wavelengths, preset.name, tangent_fields(preset), textures)


class GltfImportError(ValueError):
    """The glTF file has no material Opaline can take over; the message says why."""


def import_glb(data: bytes) -> dict[str, Any]:
    """Request fields (material and wavelengths) from a .glb's first material."""
    try:
        document = load_document(data)
    except ValueError as exc:
        raise GltfImportError(str(exc)) from None
    if not document.materials:
        raise GltfImportError("the glTF file has no material")
    material = document.materials[0]
    extras = material.extras if isinstance(material.extras, dict) else {}
    ours = extras.get(EXTRAS_KEY)
    if isinstance(ours, str):
        ours = json.loads(ours)
    if isinstance(ours, dict) and isinstance(ours.get("material"), dict):
        fields = {k: v for k, v in ours["material"].items() if k in MATERIAL_FIELDS}
        fields["wavelengths"] = int(ours.get("wavelengths", 0))
        tangents = ours.get("tangents") or {}
        fields.update({k: v for k, v in tangents.items() if k in ("tangent_field", "tangent_axis")})
        return fields
    if IRIDESCENCE in (material.extensions or {}):
        try:
            return thin_film_fields(material)
        except ValueError as exc:
            raise GltfImportError(str(exc)) from None
    raise GltfImportError("the material carries neither Opaline parameters (extras.opaline) "
                          f"nor {IRIDESCENCE}")
