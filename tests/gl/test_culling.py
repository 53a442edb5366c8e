"""Back faces are culled only where nobody could see them, so culling does not change images.

The topology tests run without GL; the renders compare draws with culling against the
same draws two-sided, from outside, from inside the sphere and from just outside it
(where the near plane would cut a window), so a culling decision that is wrong for a view
shows as a different image.
"""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl.culling import Culling
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.scene import closed
from opaline.scene.closed import orientation
from opaline.scene.geometry import annulus, box, sphere


def perspective(near: float, far: float = 100.0, fov_deg: float = 40.0) -> np.ndarray:
    f = 1.0 / np.tan(np.radians(fov_deg) / 2.0)
    return np.array([[f, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])


def looking_down_z(eye_z: float, near: float) -> np.ndarray:
    """A camera at (0, 0, eye_z) looking toward -z, laid out as the renderer's matrices
    are (for row vectors)."""
    view = np.eye(4)
    view[2, 3] = -eye_z
    return (perspective(near) @ view).T


def test_generated_closed_meshes_are_closed_and_wound_outward():
    # The sphere's seam and poles repeat positions under other indices: welding joins them.
    mesh = sphere(segments=48, rings=24)
    assert orientation(mesh.positions, mesh.indices) == 1
    assert orientation(mesh.positions, mesh.indices[:, ::-1]) == -1
    cube = box((1.0, 2.0, 0.5))
    assert orientation(cube.positions, cube.indices) == 1


def test_open_torn_or_inconsistent_meshes_are_not_closed():
    mesh = sphere(segments=48, rings=24)
    assert orientation(mesh.positions, mesh.indices[1:]) == 0  # a hole
    flipped = mesh.indices.copy()
    flipped[100] = flipped[100, ::-1]
    assert orientation(mesh.positions, flipped) == 0  # one triangle wound the other way
    doubled = np.concatenate([mesh.indices, mesh.indices[:1], mesh.indices[:1, ::-1]])
    assert orientation(mesh.positions, doubled) == 0  # an edge shared by four triangles
    disc = annulus(0.2, 1.0, segments=64)
    assert orientation(disc.positions, disc.indices) == 0
    assert orientation(np.zeros((3, 3)), np.array([[0, 1, 2]])) == 0


def shifted(mesh, offset: float, flip: bool = False):
    """A half-size copy of the mesh moved along x (wound the other way if ``flip``): the
    two parts' volumes do not cancel, so only a per-part check can tell."""
    positions = 0.5 * mesh.positions + np.array([offset, 0.0, 0.0], dtype=np.float32)
    return positions, mesh.indices[:, ::-1] if flip else mesh.indices


def test_every_part_must_be_wound_the_same_way_out():
    """Two spheres side by side are closed; with one of them turned inside out (a bad export)
    each part is still closed and consistent, but culling would show the inside of its near
    side, so the mesh is refused. A double-sided sheet (two faces back to back) is closed with
    no volume: refused too."""
    mesh = sphere(segments=32, rings=16)
    n = len(mesh.positions)
    for flip, expected in ((False, 1), (True, 0)):
        second, indices = shifted(mesh, 3.0, flip)
        positions = np.concatenate([mesh.positions, second])
        assert orientation(positions, np.concatenate([mesh.indices, indices + n])) == expected
    quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float32)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    sheet = np.concatenate([faces, faces[:, ::-1]])
    assert orientation(quad, sheet) == 0
    positions = np.concatenate([mesh.positions, quad + 3.0])
    assert orientation(positions, np.concatenate([mesh.indices, sheet + n])) == 0


def test_parts_touching_at_a_vertex_are_still_two_parts():
    """A half-size sphere standing on the big one's pole (welded into one vertex): parts
    are joined across edges, not vertices, so the small one turned inside out is found."""
    mesh = sphere(segments=32, rings=16)
    n = len(mesh.positions)
    small = 0.5 * mesh.positions + np.array([0.0, 1.5, 0.0], dtype=np.float32)
    positions = np.concatenate([mesh.positions, small])
    for flip, expected in ((False, 1), (True, 0)):
        indices = mesh.indices[:, ::-1] if flip else mesh.indices
        assert orientation(positions, np.concatenate([mesh.indices, indices + n])) == expected


def test_unused_vertices_neither_count_nor_cost():
    """A file may carry vertices no triangle uses: far away, they must not widen the box
    culling tests against the near plane, nor coarsen the weld."""
    mesh = sphere(segments=32, rings=16)
    far = np.concatenate([mesh.positions, np.full((1000, 3), 1e6, dtype=np.float32)])
    assert orientation(far, mesh.indices) == 1
    cull = Culling(far, mesh.indices)
    assert cull.corners.max() == pytest.approx(1.0)
    assert cull.front_face(np.eye(4), looking_down_z(3.4, 0.05)) == "ccw"


def test_meshes_over_the_limit_are_not_checked(monkeypatch):
    """The check's memory grows with the triangles: past the limit a mesh is drawn two-sided."""
    mesh = sphere(segments=48, rings=24)
    monkeypatch.setattr(closed, "MAX_TRIANGLES", len(mesh.indices) - 1)
    assert orientation(mesh.positions, mesh.indices) == 0
    monkeypatch.setattr(closed, "MAX_TRIANGLES", len(mesh.indices))
    assert orientation(mesh.positions, mesh.indices) == 1


def test_culling_needs_a_closed_mesh_and_its_box_in_front_of_the_near_plane():
    mesh = sphere(segments=48, rings=24)
    cull = Culling(mesh.positions, mesh.indices)
    model = np.eye(4)
    assert cull.front_face(model, looking_down_z(3.4, 0.05)) == "ccw"
    # A mirror turns the winding on screen: the front faces are then the clockwise ones.
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    assert cull.front_face(mirror, looking_down_z(3.4, 0.05)) == "cw"
    reversed_cull = Culling(mesh.positions, mesh.indices[:, ::-1])
    assert reversed_cull.front_face(model, looking_down_z(3.4, 0.05)) == "cw"
    # Inside the sphere only back faces are seen.
    assert cull.front_face(model, looking_down_z(0.5, 0.05)) is None
    # Outside, but the near plane (at 0.8) cuts the sphere open.
    assert cull.front_face(model, looking_down_z(1.5, 0.8)) is None
    disc = annulus(0.2, 1.0, segments=64)
    assert Culling(disc.positions, disc.indices).front_face(
        model, looking_down_z(3.4, 0.05)) is None


def render_pixels(renderer, preset: str, **fields) -> np.ndarray:
    job = resolve(RenderRequest(preset=preset, width=96, height=96, **fields), get_preset(preset))
    return renderer.render(job).pixels


@pytest.mark.gl
@pytest.mark.parametrize(("preset", "fields", "culled"), [
    ("sphere", {"quality": "draft"}, True),
    ("sphere", {"quality": "standard", "samples": 4}, True),
    ("perturbed-cube", {"quality": "draft", "camera_azimuth": 200.0}, True),
    ("soap-bubble", {"quality": "draft", "transparent": True}, True),
    ("sphere", {"quality": "draft", "camera_distance": 0.2}, False),  # inside
    ("sphere", {"quality": "draft", "camera_distance": 0.3}, None),   # at the surface
    ("cd-rom", {"quality": "draft"}, False),  # open
])
def test_culled_renders_equal_two_sided_ones(renderer, monkeypatch, preset, fields, culled):
    decisions = []
    decide = Culling.front_face

    def spy(self, *args):
        decisions.append(decide(self, *args))
        return decisions[-1]

    monkeypatch.setattr(Culling, "front_face", spy)
    pixels = render_pixels(renderer, preset, **fields)
    if culled is not None:
        assert (decisions[-1] is not None) == culled, decisions
    monkeypatch.setattr(Culling, "front_face", lambda self, *args: None)
    two_sided = render_pixels(renderer, preset, **fields)
    # Along a silhouette a back face shares its edge with a front face at the same depth,
    # and may win the depth test there: the one place culling changes a pixel (for the
    # better). A wrong decision (culling from inside, or the wrong winding) blanks areas.
    differs = np.any(pixels != two_sided, axis=-1)
    assert differs.sum() <= 4, np.argwhere(differs)


@pytest.mark.gl
def test_a_users_closed_mesh_is_culled_and_looks_the_same(local, monkeypatch, tmp_path):
    """A torus from a .glb (UV seams: welding joins them) is found closed and culled."""
    from mesh_helpers import mesh_bytes

    path = tmp_path / "torus.glb"
    path.write_bytes(mesh_bytes("glb"))
    request = RenderRequest(preset="sphere", mesh=str(path), width=96, height=80,
                            quality="draft", camera_azimuth=30.0, camera_elevation=25.0)
    decisions = []
    decide = Culling.front_face
    monkeypatch.setattr(Culling, "front_face",
                        lambda self, *args: decisions.append(decide(self, *args)) or decisions[-1])
    culled = local.render_array(request)
    assert decisions and decisions[-1] == "ccw"
    monkeypatch.setattr(Culling, "front_face", lambda self, *args: None)
    two_sided = local.render_array(request)
    differs = np.any(np.abs(culled - two_sided) > 1e-6, axis=-1)
    assert culled[..., 3].mean() > 0.1 and differs.sum() <= 4, np.argwhere(differs)
