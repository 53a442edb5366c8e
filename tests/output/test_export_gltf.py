"""The .glb export: pygltflib loads it, the mesh comes back as it went, the material's
parameters re-import exactly, and the re-imported material renders on the .glb's mesh."""

from __future__ import annotations

import io
import json

import numpy as np
import pygltflib
import pytest
import trimesh

from opaline.cli import main as cli
from opaline.local.export import export_material, import_material
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import build_assets, get_preset
from opaline.output.gltf import GltfImportError, export_glb, import_glb


@pytest.mark.parametrize("preset", ["cd-rom", "sphere", "perturbed-cube"])
def test_glb_loads_and_round_trips(preset):
    request = RenderRequest(preset=preset, mu_f=6.25, theta1=0.3, kd=0.2, wavelengths=16)
    data = export_material(request, "glb")
    document = pygltflib.GLTF2.load_from_bytes(data)
    assert document.asset.version == "2.0" and len(document.meshes) == 1
    attributes = document.meshes[0].primitives[0].attributes
    assert None not in (attributes.POSITION, attributes.NORMAL, attributes.TANGENT,
                        attributes.TEXCOORD_0)
    mesh, _ = build_assets(get_preset(preset))
    loaded = trimesh.load(io.BytesIO(data), file_type="glb", force="mesh", process=False)
    assert len(loaded.faces) == mesh.triangle_count
    np.testing.assert_allclose(np.sort(loaded.vertices, axis=0),
                               np.sort(mesh.positions, axis=0), atol=1e-6)
    fields = import_glb(data)
    assert fields["mu_f"] == 6.25 and fields["theta1"] == 0.3 and fields["kd"] == 0.2
    assert fields["wavelengths"] == 16
    assert (fields.get("tangent_field") == "concentric") == (preset == "cd-rom")


def test_import_refuses_what_it_cannot_take():
    with pytest.raises(GltfImportError, match="not a readable"):
        import_glb(b"glTF" + bytes(30))
    mesh, _ = build_assets(get_preset("sphere"))
    document = pygltflib.GLTF2.load_from_bytes(export_glb(mesh, Material()))
    document.materials[0].extras = {}
    with pytest.raises(GltfImportError, match="extras.opaline"):
        import_glb(b"".join(document.save_to_bytes()))
    for film, why in [({}, "film is off"), ({"iridescenceFactor": 1, "iridescenceIor": 9.0},
                                            "film_ior")]:
        document.materials[0].extensions = {"KHR_materials_iridescence": film}
        with pytest.raises(GltfImportError, match=why):
            import_glb(b"".join(document.save_to_bytes()))


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_cli_export_import_render(tmp_path, capsys):
    glb, material, image = tmp_path / "cd.glb", tmp_path / "cd.json", tmp_path / "cd.png"
    assert cli.main(["export", "cd-rom", "--set", "mu_f=6", "-o", str(glb)]) == 0
    assert cli.main(["import", str(glb), "--preset", "cd-rom", "-o", str(material)]) == 0
    fields = json.loads(material.read_text())
    assert fields["mesh"] == "cd.glb" and fields["mu_f"] == 6.0
    assert cli.main(["render", str(material), "--size", "64", "--quality", "draft",
                     "-o", str(image)]) == 0, capsys.readouterr().err
    glsl = tmp_path / "cd.glsl"
    assert cli.main(["export", "cd-rom", "-o", str(glsl)]) == 0
    assert "vec3 opaline_radiance(vec3 n, vec3 t, vec3 l, vec3 v)" in glsl.read_text()
    capsys.readouterr()
    # What no render could read is not written: an unknown preset, JSON in a .toml.
    for argv, said in ((["--preset", "nope", "-o", str(tmp_path / "n.json")], "nope"),
                       (["-o", str(tmp_path / "b.toml")], "name it .json")):
        assert cli.main(["import", str(glb), *argv]) == 2
        assert said in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cd.glb", "cd.glsl", "cd.json",
                                                         "cd.png"]


def test_a_glb_cut_short_is_said_so():
    """A truncated .glb was read by pygltflib as a document without materials: "the glTF
    file has no material"."""
    data = export_material({"preset": "sphere"}, "glb")
    with pytest.raises(GltfImportError, match=f"cut short: {len(data) // 2} of its {len(data)}"):
        import_glb(data[:len(data) // 2])


def test_import_material_names_the_glb_as_mesh(tmp_path):
    path = tmp_path / "s.glb"
    path.write_bytes(export_material({"preset": "sphere", "alpha": 3.0}, "glb"))
    fields = import_material(path)
    assert fields["mesh"] == str(path) and fields["alpha"] == 3.0
    RenderRequest.model_validate(fields)
