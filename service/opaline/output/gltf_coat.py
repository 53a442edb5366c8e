"""A clear coat in glTF: KHR_materials_clearcoat both ways.

Export writes clearcoatFactor = coat_weight and clearcoatRoughnessFactor = coat_roughness
(both mean what they mean in KHR: the coat's layering is KHR's, model/coat.py). KHR fixes
the coat's index at 1.5; another index travels in extras.opaline alone, which Opaline
imports back. Import reads the two factors from another tool's file (no texture: a
clearcoatTexture or clearcoatRoughnessTexture is named in the refusal, not dropped
silently).
"""

from __future__ import annotations

from typing import Any

from opaline.model.material import Material

CLEARCOAT = "KHR_materials_clearcoat"
TEXTURES = ("clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture")


def coat_extensions(material: Material) -> dict[str, Any]:
    """The material's KHR_materials_clearcoat entry; none without a coat."""
    if material.coat_weight <= 0.0:
        return {}
    return {CLEARCOAT: {"clearcoatFactor": float(material.coat_weight),
                        "clearcoatRoughnessFactor": float(material.coat_roughness)}}


def coat_fields(extensions: dict[str, Any]) -> dict[str, Any]:
    """Request fields of a material's KHR_materials_clearcoat (none without it); ValueError
    naming the key where it holds what Opaline cannot draw."""
    coat = extensions.get(CLEARCOAT)
    if coat is None:
        return {}
    if not isinstance(coat, dict):
        raise ValueError(f"{CLEARCOAT} must be an object")
    for key in TEXTURES:
        if key in coat:
            raise ValueError(f"{CLEARCOAT}.{key}: a coat texture is not drawn by Opaline "
                             "(one coat weight and roughness per material)")
    fields = {"coat_weight": _unit(coat, "clearcoatFactor", 0.0),
              "coat_roughness": _unit(coat, "clearcoatRoughnessFactor", 0.0)}
    return fields if fields["coat_weight"] > 0.0 else {}


def _unit(block: dict[str, Any], key: str, default: float) -> float:
    value = block.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 <= value <= 1.0:
        raise ValueError(f"{CLEARCOAT}.{key} must be a number in 0 … 1, not {value!r}")
    return float(value)
