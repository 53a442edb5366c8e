"""Thin-film materials in glTF: KHR_materials_iridescence (and KHR_materials_ior) both ways.

Export maps a ``thin-film`` material exactly: iridescenceFactor = film_weight (both
mix the bare base's Fresnel term with the film's by it), iridescenceIor = film_ior,
iridescenceThicknessMinimum/Maximum = film_thickness_min/max (nm), and the base
material's KHR_materials_ior ior = substrate_ior, because KHR's Airy term takes
the base material's IOR as the medium under the film (n3), as Opaline does. A
dielectric substrate is written as a dielectric base (metallicFactor 0); a
conductor (docs/physics.md §1.2) as a metallic base (metallicFactor 1, no
KHR_materials_ior) whose colour is the metal's bare F0, which KHR viewers use as
the metal's reflectance under the film; a metallic file imports back as the
``artist`` metal of that F0 (edge tint white). A preset's thickness field is written as
iridescenceThicknessTexture: 8-bit grey RGB (KHR reads G), 1/255 of the range
per step; a user's .glb's own textures go back as they came (scene.gltf_film). A stack
(film_stack_pairs > 0) is not a KHR film: it is written without the extension, in the
extras only.

Import reads the same names back, iridescenceFactor into film_weight (a factor of 0,
no film, is refused: that is a plain material), with the extension's defaults (ior
1.3, thickness 100-400 nm) where a key is absent and the glTF base ior 1.5 without
KHR_materials_ior. The imported material file draws the .glb itself as its mesh, and a
.glb with a thickness texture draws its film with it, in its own UVs
(scene.gltf_film), and one with an iridescenceTexture (KHR's per-texel factor, R)
weighs its film by it texel by texel, times film_weight; both go back to the export.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np
import pygltflib as gl
from PIL import Image
from pydantic import ValidationError

from opaline.model import metals
from opaline.model.coat import exponent_from_roughness
from opaline.model.params import Material, MaterialFields
from opaline.model.spectrum import rgb_weights
from opaline.output.gltf_coat import coat_fields
from opaline.scene.gltf_film import IRIDESCENCE

IOR = "KHR_materials_ior"
# KHR_materials_iridescence's defaults (iridescenceFactor's is 0: no film).
KHR_IOR, KHR_THICKNESS_MIN, KHR_THICKNESS_MAX = 1.3, 100.0, 400.0
GLTF_BASE_IOR = 1.5  # glTF's dielectric base without KHR_materials_ior
F0_WAVELENGTHS = 128  # a conductor's base colour: its bare F0, converged (docs/physics.md §1.2)


def is_thin_film(material: Material) -> bool:
    """A film KHR_materials_iridescence can say: one layer. A stack (film_stack_pairs > 0)
    has no KHR form; its .glb carries it in extras.opaline alone, which Opaline imports."""
    return material.iridescence == "thin-film" and material.film_stack_pairs == 0


def thin_film_extensions(material: Material, textures: dict[str, int]) -> dict[str, Any]:
    """The material's ``extensions`` entries; ``textures``: the texture index of each KHR
    texture written (iridescenceThicknessTexture, iridescenceTexture)."""
    film: dict[str, Any] = {
        "iridescenceFactor": float(material.film_weight),
        "iridescenceIor": float(material.film_ior),
        "iridescenceThicknessMinimum": float(material.film_thickness_min),
        "iridescenceThicknessMaximum": float(material.film_thickness_max),
    }
    for key, index in textures.items():
        film[key] = {"index": index, "texCoord": 0}
    if material.substrate == "conductor":  # a metallic base: no index under the film
        return {IRIDESCENCE: film}
    return {IRIDESCENCE: film, IOR: {"ior": float(material.substrate_ior)}}


def base_colour_and_metallic(material: Material) -> tuple[list[float], float]:
    """The base under a film: a dielectric's diffuse colour (kd·albedo, metallic 0), or a
    conductor's bare F0 in linear sRGB (metallic 1), the colour KHR viewers take as the
    metal's reflectance under the film."""
    if material.substrate == "conductor":
        f0 = metals.bare_f0(metals.substrate_for(material, F0_WAVELENGTHS)) @ rgb_weights(
            F0_WAVELENGTHS)
        return [float(c) for c in np.clip(f0, 0.0, 1.0)], 1.0
    return [float(c) * min(material.kd, 1.0) for c in material.albedo], 0.0


def field_png(field: np.ndarray) -> bytes:
    """The [0, 1] field as a grey RGB PNG, row 0 at the top: Opaline's fields are stored
    with v = 1 on row 0, and the export writes glTF's t = 1 - v, so rows map unchanged."""
    grey = np.round(np.clip(field, 0.0, 1.0) * 255.0).astype(np.uint8)
    out = io.BytesIO()
    Image.fromarray(np.repeat(grey[:, :, None], 3, axis=2), "RGB").save(out, "PNG")
    return out.getvalue()


def add_film_texture(document: gl.GLTF2, buffer_view: int) -> int:
    """Image, repeating mipmapped sampler (the fields tile) and texture; the texture's index."""
    document.images.append(gl.Image(bufferView=buffer_view, mimeType="image/png"))
    document.samplers.append(gl.Sampler(magFilter=gl.LINEAR, minFilter=gl.LINEAR_MIPMAP_LINEAR,
                                        wrapS=gl.REPEAT, wrapT=gl.REPEAT))
    document.textures.append(gl.Texture(sampler=len(document.samplers) - 1,
                                        source=len(document.images) - 1))
    return len(document.textures) - 1


def _number(block: dict[str, Any], key: str, default: float) -> float:
    value = block.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{key} must be a number, not {value!r}")
    return float(value)


def thin_film_fields(material: gl.Material) -> dict[str, Any]:
    """Request fields of a material carrying KHR_materials_iridescence (ValueError if the
    film is off or outside Opaline's ranges). The base's roughness becomes the A-S lobe's
    exponents (the inverse of the export's stand-in), its colour the diffuse albedo."""
    extensions = material.extensions or {}
    film = extensions.get(IRIDESCENCE)
    ior = extensions.get(IOR) or {}
    if not isinstance(film, dict) or not isinstance(ior, dict):
        raise ValueError(f"{IRIDESCENCE} must be an object")
    factor = _number(film, "iridescenceFactor", 0.0)
    if factor <= 0.0:
        raise ValueError(f"{IRIDESCENCE} has iridescenceFactor 0: the film is off")
    pbr = material.pbrMetallicRoughness or gl.PbrMetallicRoughness()
    metallic = pbr.metallicFactor if pbr.metallicFactor is not None else 1.0
    colour = list(pbr.baseColorFactor or [1.0, 1.0, 1.0, 1.0])[:3]
    exponent = exponent_from_roughness(
        pbr.roughnessFactor if pbr.roughnessFactor is not None else 1.0)
    fields = {
        "iridescence": "thin-film",
        "film_weight": factor,
        "film_ior": _number(film, "iridescenceIor", KHR_IOR),
        "film_thickness_min": _number(film, "iridescenceThicknessMinimum", KHR_THICKNESS_MIN),
        "film_thickness_max": _number(film, "iridescenceThicknessMaximum", KHR_THICKNESS_MAX),
        "substrate_ior": _number(ior, "ior", GLTF_BASE_IOR),
        "ex": exponent, "ey": exponent, "ks": 1.0,
        "kd": float(np.clip(1.0 - metallic, 0.0, 1.0)),
        "albedo": [float(np.clip(c, 0.0, 1.0)) for c in colour],
    }
    if metallic >= 1.0:  # a film on a metal: its base colour is the metal's F0
        fields.update(substrate="conductor", metal="artist", kd=0.0,
                      metal_f0=fields["albedo"], metal_edge_tint=[1.0, 1.0, 1.0])
    fields.update(coat_fields(extensions))
    try:
        MaterialFields.model_validate(fields)
    except ValidationError as exc:
        problems = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())
        raise ValueError(f"{IRIDESCENCE} outside Opaline's ranges: {problems}") from None
    return fields
