"""Thin-film materials leave as KHR_materials_iridescence (+ KHR_materials_ior) with the
exact values, a .glb carrying only the extension imports as a thin film and renders, and
export → import keeps every field."""

from __future__ import annotations

import io
import math

import numpy as np
import pygltflib
import pytest
from PIL import Image

from opaline.local.export import export_material, import_material
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import build_assets, build_thickness, get_preset
from opaline.output.gltf import export_glb, import_glb

FILM = {"iridescence": "thin-film", "film_ior": 1.45, "film_thickness_min": 120.0,
        "film_thickness_max": 730.0, "substrate_ior": 1.62}
FIELDS = tuple(FILM)


def _load(data: bytes) -> pygltflib.GLTF2:
    return pygltflib.GLTF2.load_from_bytes(data)


def test_thin_film_exports_the_extension_exactly():
    document = _load(export_material({"preset": "sphere", **FILM}, "glb"))
    assert {"KHR_materials_iridescence", "KHR_materials_ior"} <= set(document.extensionsUsed)
    material = document.materials[0]
    assert material.extensions["KHR_materials_iridescence"] == {
        "iridescenceFactor": 1.0, "iridescenceIor": 1.45, "iridescenceThicknessMinimum": 120.0,
        "iridescenceThicknessMaximum": 730.0}  # the sphere has no thickness field
    assert material.extensions["KHR_materials_ior"] == {"ior": 1.62}
    assert material.pbrMetallicRoughness.metallicFactor == 0.0  # a dielectric under the film
    assert material.extras["opaline"]["material"]["film_ior"] == 1.45
    # The paper's materials carry no extension.
    plain = _load(export_material({"preset": "sphere"}, "glb"))
    assert not plain.extensionsUsed and not plain.materials[0].extensions


def test_thickness_field_becomes_the_thickness_texture():
    document = _load(export_material({"preset": "oil-film"}, "glb"))
    film = document.materials[0].extensions["KHR_materials_iridescence"]
    texture = document.textures[film["iridescenceThicknessTexture"]["index"]]
    view = document.bufferViews[document.images[texture.source].bufferView]
    blob = document.binary_blob()[view.byteOffset:view.byteOffset + view.byteLength]
    green = np.asarray(Image.open(io.BytesIO(blob)).convert("RGB"))[:, :, 1] / 255.0
    field = build_thickness(get_preset("oil-film"))
    assert green.shape == field.shape
    np.testing.assert_allclose(green, field, atol=0.5 / 255 + 1e-6)


def _khr_only(film: dict, ior: float | None, roughness: float = 0.3) -> bytes:
    """A .glb as another tool writes it: the sphere with a KHR material and no extras."""
    mesh, _ = build_assets(get_preset("sphere"))
    document = _load(export_glb(mesh, Material()))
    extensions = {"KHR_materials_iridescence": film}
    if ior is not None:
        extensions["KHR_materials_ior"] = {"ior": ior}
    document.materials[0] = pygltflib.Material(
        name="bubble", extensions=extensions,
        pbrMetallicRoughness=pygltflib.PbrMetallicRoughness(
            baseColorFactor=[0.1, 0.2, 0.3, 1.0], metallicFactor=0.0, roughnessFactor=roughness))
    document.extensionsUsed = list(extensions)
    return b"".join(document.save_to_bytes())


def test_khr_only_glb_imports_as_thin_film():
    film = {"iridescenceFactor": 1.0, "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 50.0,
            "iridescenceThicknessMaximum": 900.0}
    fields = import_glb(_khr_only(film, 1.2))
    assert {k: fields[k] for k in FIELDS} == {
        "iridescence": "thin-film", "film_ior": 1.8, "film_thickness_min": 50.0,
        "film_thickness_max": 900.0, "substrate_ior": 1.2}
    assert fields["albedo"] == [0.1, 0.2, 0.3] and fields["kd"] == 1.0
    assert fields["ex"] == fields["ey"] == pytest.approx(2 / 0.3**4 - 2)  # α = r²
    # Absent keys take the extension's defaults, the base ior glTF's 1.5.
    fields = import_glb(_khr_only({"iridescenceFactor": 1.0}, None))
    assert {k: fields[k] for k in FIELDS[1:]} == {
        "film_ior": 1.3, "film_thickness_min": 100.0, "film_thickness_max": 400.0,
        "substrate_ior": 1.5}


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_khr_only_glb_renders(tmp_path):
    from opaline import render_array

    path = tmp_path / "film.glb"
    path.write_bytes(_khr_only({"iridescenceFactor": 1.0, "iridescenceIor": 1.33,
                                "iridescenceThicknessMaximum": 450.0}, 1.0, roughness=0.15))
    fields = import_material(path)
    RenderRequest.model_validate(fields)
    image = render_array({**fields, "width": 48, "height": 48, "quality": "draft"})
    rgb = image[..., :3][image[..., 3] > 0.5]
    assert rgb.size and np.isfinite(rgb).all() and rgb.max() > 0.0
    # A 450 nm soap film is coloured: its channels differ somewhere on the sphere.
    assert np.ptp(rgb, axis=1).max() > 0.02


@pytest.mark.parametrize("preset", ["sphere", "oil-film", "soap-bubble"])
def test_round_trip_keeps_thin_film_fields(preset):
    request = RenderRequest(preset=preset, **FILM)
    fields = import_glb(export_material(request, "glb"))
    assert {k: fields[k] for k in FIELDS} == FILM
    # Without extras the extension alone gives the same film.
    document = _load(export_material(request, "glb"))
    document.materials[0].extras = {}
    fields = import_glb(b"".join(document.save_to_bytes()))
    assert {k: fields[k] for k in FIELDS} == FILM


def ggx_half_width(alpha: float) -> float:
    """θ_h where GGX's D = α²/(π((α² - 1)cos²θ + 1)²) falls to half its peak:
    (1 + tan²θ/α²)² = 2."""
    return math.atan(alpha * math.sqrt(math.sqrt(2.0) - 1.0))


def phong_half_width(exponent: float) -> float:
    """θ_h where the isotropic A-S lobe, cos^n θ_h, falls to half its peak."""
    return math.acos(0.5 ** (1.0 / exponent))


@pytest.mark.parametrize("roughness", [0.02, 0.05, 0.1, 0.2, 0.3, 0.5])
def test_imported_roughness_has_the_ggx_lobe_width(roughness):
    """KHR roughness r is GGX's α = r²: the imported A-S lobe is as wide as that GGX lobe
    at half maximum, within the shapes' difference (A-S with n = 2/α² - 2 has Beckmann's
    width, 1.29× GGX's at half maximum; 1.34× at r = 0.5, and wider toward r = 1, 1.5× at
    0.7 and 2.1× at 0.9, where the -2 that keeps n ≥ 0 counts). Read as α (the old
    mapping) it was about 1/r times too wide: 13× at r = 0.1."""
    fields = import_glb(_khr_only({"iridescenceFactor": 1.0}, 1.5, roughness=roughness))
    exponent = 2.0 / roughness**4 - 2.0
    ratio = phong_half_width(min(exponent, 1e6)) / ggx_half_width(roughness**2)
    assert fields["ex"] == fields["ey"] == pytest.approx(min(exponent, 1e6))
    if exponent <= 1e6:  # beyond: the exponent's range, narrower than fp32 resolves anyway
        assert 1.25 < ratio < 1.35
    if roughness == 0.1:
        assert fields["ex"] == pytest.approx(19998.0)  # issue 23's example: not 198


@pytest.mark.parametrize("exponent", [0.0, 2.0, 20.0, 198.0, 2e4, 1e6])
def test_exported_roughness_inverts_the_import(exponent):
    """Export writes the roughness whose import gives the exponent back (while the
    roughness is inside glTF's usual clamp, 0.02 … 1)."""
    request = RenderRequest(preset="sphere", **FILM, mdf="ashikhmin", ex=exponent, ey=exponent)
    document = _load(export_material(request, "glb"))
    roughness = document.materials[0].pbrMetallicRoughness.roughnessFactor
    alpha = math.sqrt(2.0 / (exponent + 2.0))
    assert roughness == pytest.approx(math.sqrt(alpha), rel=1e-6)  # not α itself
    document.materials[0].extras = {}
    back = import_glb(b"".join(document.save_to_bytes()))
    assert back["ex"] == pytest.approx(exponent, rel=1e-4, abs=1e-6)


def test_film_on_a_metal_exports_a_metallic_base_of_its_f0():
    """A conductor under the film (issue 23) is a metallic base whose colour is the bare
    metal's F0 (gold: warm), with no KHR_materials_ior; the KHR-only file imports as the
    artist metal of that F0, and the extras give back the tabulated metal exactly."""
    request = RenderRequest(preset="sphere", **FILM, substrate="conductor", metal="gold")
    data = export_material(request, "glb")
    material = _load(data).materials[0]
    pbr = material.pbrMetallicRoughness
    assert pbr.metallicFactor == 1.0 and "KHR_materials_ior" not in material.extensions
    red, green, blue = pbr.baseColorFactor[:3]
    assert red > 0.95 and 0.65 < green < 0.8 and 0.3 < blue < 0.42  # published: 1, 0.78, 0.34
    fields = import_glb(data)
    assert fields["substrate"] == "conductor" and fields["metal"] == "gold"
    document = _load(data)
    document.materials[0].extras = {}
    fields = import_glb(b"".join(document.save_to_bytes()))
    assert fields["substrate"] == "conductor" and fields["metal"] == "artist"
    assert fields["metal_f0"] == pytest.approx([red, green, blue]) and fields["kd"] == 0.0
    RenderRequest.model_validate(fields)


def test_partial_film_round_trips_as_its_factor():
    """iridescenceFactor is film_weight both ways (issue 23): a KHR-only .glb whose factor
    is 0.5 imports as a half-weight film, not a whole one, and that material exports the
    factor 0.5 again (with the film's other values, extras or not); a factor beyond 1 is
    refused naming the field."""
    film = {"iridescenceFactor": 0.5, "iridescenceIor": 1.6,
            "iridescenceThicknessMinimum": 80.0, "iridescenceThicknessMaximum": 520.0}
    fields = import_glb(_khr_only(film, 1.4))
    assert fields["film_weight"] == 0.5
    request = RenderRequest.model_validate({"preset": "oil-film", **fields})
    data = export_material(request, "glb")
    exported = _load(data).materials[0].extensions["KHR_materials_iridescence"]
    assert {k: exported[k] for k in film} == film
    assert "iridescenceThicknessTexture" in exported  # the preset's field, as before
    assert import_glb(data)["film_weight"] == 0.5  # through the extras
    document = _load(data)
    document.materials[0].extras = {}
    assert import_glb(b"".join(document.save_to_bytes()))["film_weight"] == 0.5
    with pytest.raises(ValueError, match="film_weight"):
        import_glb(_khr_only({**film, "iridescenceFactor": 1.5}, 1.4))
