"""A clear coat leaves as KHR_materials_clearcoat with its weight and roughness, on a film
and on the paper's material alike; another tool's .glb with a film under a coat imports
with both; a coat texture or a factor outside 0 … 1 is refused naming the key."""

from __future__ import annotations

import pygltflib
import pytest

from opaline.local.export import export_material
from opaline.model.params import Material
from opaline.model.presets import build_assets, get_preset
from opaline.output.gltf import GltfImportError, export_glb, import_glb

CLEARCOAT = "KHR_materials_clearcoat"
FILM = {"iridescenceFactor": 1.0, "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 50.0,
        "iridescenceThicknessMaximum": 900.0}


def _load(data: bytes) -> pygltflib.GLTF2:
    return pygltflib.GLTF2.load_from_bytes(data)


@pytest.mark.parametrize("fields", [{"preset": "coated-paint"},
                                    {"preset": "sphere", "coat_weight": 0.4,
                                     "coat_roughness": 0.25}])
def test_a_coat_exports_as_the_extension(fields):
    document = _load(export_material(fields, "glb"))
    material = Material(**{k: v for k, v in fields.items() if k != "preset"}
                        or get_preset("coated-paint").defaults.model_dump(
                            include=set(Material.model_fields), exclude_none=True))
    assert CLEARCOAT in document.extensionsUsed
    assert document.materials[0].extensions[CLEARCOAT] == {
        "clearcoatFactor": material.coat_weight,
        "clearcoatRoughnessFactor": material.coat_roughness}


def test_no_coat_no_extension():
    document = _load(export_material({"preset": "oil-film"}, "glb"))
    assert CLEARCOAT not in (document.extensionsUsed or [])
    assert CLEARCOAT not in document.materials[0].extensions


def other_tools(coat: dict) -> bytes:
    """The sphere with a film under a coat, as another tool writes it: no extras."""
    mesh, _ = build_assets(get_preset("sphere"))
    document = _load(export_glb(mesh, Material()))
    extensions = {"KHR_materials_iridescence": FILM, CLEARCOAT: coat}
    document.materials[0] = pygltflib.Material(
        name="paint", extensions=extensions,
        pbrMetallicRoughness=pygltflib.PbrMetallicRoughness(metallicFactor=0.0,
                                                            roughnessFactor=0.4))
    document.extensionsUsed = list(extensions)
    return b"".join(document.save_to_bytes())


def test_another_tools_coat_imports_with_its_film():
    fields = import_glb(other_tools({"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.1}))
    assert (fields["coat_weight"], fields["coat_roughness"]) == (0.7, 0.1)
    assert fields["film_ior"] == 1.8
    # KHR's defaults: roughness 0; a factor of 0 is no coat.
    assert import_glb(other_tools({"clearcoatFactor": 0.5}))["coat_roughness"] == 0.0
    assert "coat_weight" not in import_glb(other_tools({}))


def test_opalines_own_coat_round_trips_with_its_index(tmp_path):
    fields = {"preset": "sphere", "coat_weight": 0.6, "coat_roughness": 0.2, "coat_ior": 1.7}
    back = import_glb(export_material(fields, "glb"))
    assert {k: back[k] for k in ("coat_weight", "coat_roughness", "coat_ior")} == {
        "coat_weight": 0.6, "coat_roughness": 0.2, "coat_ior": 1.7}


@pytest.mark.parametrize("coat,message", [
    ({"clearcoatFactor": 1.5}, "clearcoatFactor must be a number in 0 … 1"),
    ({"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": "rough"},
     "clearcoatRoughnessFactor must be a number"),
    ({"clearcoatFactor": 1.0, "clearcoatTexture": {"index": 0}}, "clearcoatTexture"),
])
def test_what_cannot_be_drawn_is_refused_naming_the_key(coat, message):
    with pytest.raises(GltfImportError, match=message):
        import_glb(other_tools(coat))
