"""Meshes from files: every format loads, tangents are orthonormal, broken files are refused,
and the CLI, the Python API and material files draw a mesh framed in the image."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mesh_helpers import FORMATS, assert_framed, broken_files, mesh_bytes, torus_with_uvs
from opaline.cli import main as cli
from opaline.gl.buffers import bounding_sphere
from opaline.model.camera import fit_matrix, framing_distance
from opaline.scene import tangents
from opaline.scene.meshfile import MeshError, parse_mesh

SMALL = {"width": 96, "height": 80, "quality": "draft"}


def assert_orthonormal_frame(mesh) -> None:
    n = mesh.normals.astype(np.float64)
    t = mesh.tangents.astype(np.float64)
    assert np.all(np.isfinite(t)) and np.all(np.isfinite(n))
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=1e-5)
    assert np.abs(np.sum(n * t, axis=1)).max() < 1e-5


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_format_loads_with_an_orthonormal_frame(fmt):
    """glTF (JSON and GLB), OBJ, PLY, STL: same triangles and bounds, unit tangents ⟂ normals."""
    mesh, summary = parse_mesh(mesh_bytes(fmt))
    reference = torus_with_uvs()
    assert summary["format"] == fmt
    assert mesh.triangle_count == len(reference.faces) == summary["triangles"]
    np.testing.assert_allclose(summary["bounds"], reference.bounds, rtol=1e-5)
    assert summary["tangents"] == ("concentric" if fmt == "stl" else "uv")  # STL has no UVs
    assert_orthonormal_frame(mesh)


def test_uv_tangents_follow_increasing_u():
    """On a plane whose u runs along x (and one mirrored, u along -x) the tangent is ±x."""
    xs, zs = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4))
    positions = np.stack([xs.ravel(), np.zeros(xs.size), zs.ravel()], 1)
    normals = np.tile((0.0, 1.0, 0.0), (len(positions), 1))
    faces = np.array([[0, 5, 1], [1, 5, 6]])
    for sign in (1.0, -1.0):
        uvs = np.stack([sign * positions[:, 0], positions[:, 2]], 1)
        t, ok = tangents.from_uvs(positions, normals, uvs, faces)
        np.testing.assert_allclose(t[[0, 1, 5, 6]], [(sign, 0, 0)] * 4, atol=1e-12)
        assert ok[[0, 1, 5, 6]].all() and not ok[2]  # vertex 2 is in no triangle


def test_fields_without_uvs():
    """Concentric circles about the axis, and a projected direction; both orthonormal even
    where they degenerate (on the axis; a normal parallel to the direction)."""
    rng = np.random.default_rng(3)
    normals = tangents._unit_rows(rng.normal(size=(200, 3)))[0]
    normals[0] = (0.0, 1.0, 0.0)
    positions = rng.normal(size=(200, 3))
    positions[1] = (0.0, 2.0, 0.0)  # on the axis
    for t in (tangents.concentric(positions, normals, (0, 1, 0), (0, 0, 0)),
              tangents.projected(normals, (0, 1, 0))):
        np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=1e-12)
        assert np.abs(np.sum(t * normals, axis=1)).max() < 1e-12
    t = tangents.concentric(positions, normals, (0, 1, 0), (0, 0, 0))
    around = np.cross((0, 1, 0), positions[5])
    assert abs(np.dot(t[5], around)) > 0  # follows the circle where it is defined
    mesh, summary = parse_mesh(mesh_bytes("stl"), field="projected", axis=(1, 0, 0))
    assert summary["tangents"] == "projected"
    assert_orthonormal_frame(mesh)
    with pytest.raises(MeshError, match="no UV"):
        parse_mesh(mesh_bytes("stl"), field="uv")


@pytest.mark.parametrize("name", sorted(broken_files()))
def test_broken_files_are_refused_with_a_reason(name):
    with pytest.raises(MeshError) as caught:
        parse_mesh(broken_files()[name])
    assert len(str(caught.value)) > 10


def test_triangle_limit():
    with pytest.raises(MeshError, match="over this service's limit of 100"):
        parse_mesh(mesh_bytes("ply"), max_triangles=100)


def test_fit_matrix_puts_the_bounds_on_a_unit_sphere():
    rng = np.random.default_rng(1)
    points = rng.normal(size=(500, 3)) * (300.0, 20.0, 7.0) + (1e3, -50.0, 4.0)
    centre, radius = bounding_sphere(points)
    fitted = np.c_[points, np.ones(len(points))] @ fit_matrix((centre, radius), (0.0, 0.5, 0.0))
    distances = np.linalg.norm(fitted[:, :3] - (0, 0.5, 0), axis=1)
    assert distances.max() == pytest.approx(1.0) and distances.min() < 0.2
    # The unit sphere at that distance touches the narrower side of the frustum, with margin.
    assert 2.5 < framing_distance(1.0, 35.0, 1.0) < 4.0


@pytest.mark.gl
@pytest.mark.parametrize("fmt", FORMATS)
def test_python_api_frames_each_format(local, tmp_path, fmt):
    from opaline.model.params import RenderRequest

    path = tmp_path / f"torus.{fmt}"
    path.write_bytes(mesh_bytes(fmt))
    linear = local.render_array(RenderRequest(preset="sphere", mesh=str(path), **SMALL))
    assert linear.shape == (80, 96, 4)
    assert_framed(linear[..., 3])
    assert linear[..., :3].max() > 0.05  # lit, not a silhouette


@pytest.mark.gl
def test_orbit_moves_the_camera_around_the_mesh(local, tmp_path):
    from opaline.model.params import RenderRequest

    path = tmp_path / "torus.glb"
    path.write_bytes(mesh_bytes("glb"))
    views = [local.render_array(RenderRequest(preset="sphere", mesh=str(path),
                                              camera_azimuth=az, camera_elevation=10, **SMALL))
             for az in (0, 90)]
    assert not np.array_equal(views[0][..., 3] > 0.5, views[1][..., 3] > 0.5)
    for view in views:
        assert_framed(view[..., 3])
    far = local.render_array(RenderRequest(preset="sphere", mesh=str(path), camera_distance=2.0,
                                           **SMALL))
    assert (far[..., 3] > 0.5).sum() < 0.5 * (views[0][..., 3] > 0.5).sum()


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_cli_and_material_file_render_a_mesh(capsys, tmp_path):
    from PIL import Image

    (tmp_path / "torus.obj").write_bytes(mesh_bytes("obj"))
    out = tmp_path / "cli.png"
    code = cli.main(["render", "sphere", "--mesh", str(tmp_path / "torus.obj"), "--size", "96x80",
                     "--quality", "draft", "--transparent", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert_framed(np.asarray(Image.open(out))[..., 3] / 255.0)
    material = tmp_path / "mine.json"  # the mesh path is relative to the material file
    material.write_text(json.dumps({"preset": "nacre", "mesh": "torus.obj", **SMALL}))
    assert cli.main(["render", str(material), "-o", str(tmp_path / "file.png")]) == 0
    assert (tmp_path / "file.png").stat().st_size > 1000
    broken = tmp_path / "broken.stl"
    broken.write_bytes(broken_files()["nan-vertex-stl"])
    assert cli.main(["render", "sphere", "--mesh", str(broken), "-o", str(tmp_path / "x.png")]) == 2
    said = capsys.readouterr().err
    assert "NaN" in said and "mesh broken.stl: " in said  # the file named, as a review asked


def test_a_zero_tangent_axis_is_named_in_plain_numbers():
    """The 422 once read tangent_axis=(np.float64(0.0), ...)."""
    with pytest.raises(MeshError, match=r"^tangent_axis=\(0\.0, 0\.0, 0\.0\) must be a finite"):
        parse_mesh(mesh_bytes("stl"), field="concentric", axis=(0, 0, 0))


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_parse_leaves_nothing_for_the_collector(fmt):
    """trimesh's objects hold reference cycles: a parse's intermediates waited for the
    collector, ~300 MB of a 2M-triangle scan, which took its worker past its memory limit
    after every render. With the collector off, none is left once a parse returns."""
    import gc

    import trimesh

    enabled = gc.isenabled()
    gc.disable()
    try:
        parse_mesh(mesh_bytes(fmt), f".{fmt}")
        left = [o for o in gc.get_objects() if isinstance(o, trimesh.Trimesh)]
    finally:
        if enabled:
            gc.enable()
    assert not left
