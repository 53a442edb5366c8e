"""Procedural meshes: attribute invariants, winding, and each shape's own promises."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from opaline.scene import geometry
from opaline.scene.geometry import Mesh
from opaline.scene.mesh import make_mesh
from opaline.scene.rings import zip_rings

UNIT_TOL = 1e-5
ORTHO_TOL = 1e-5

MESHES = {
    "sphere": lambda: geometry.sphere(1.5, 24, 12),
    "sphere-min": lambda: geometry.sphere(1.0, 3, 2),
    "annulus": lambda: geometry.annulus(0.3, 1.2, 48, 3),  # narrow: the uniform grid
    "annulus-cd": lambda: geometry.annulus(0.125, 1.0, 64, 3),  # coarser rings inside
    "box": lambda: geometry.box((1.0, 2.0, 3.0)),
    "wavy": lambda: geometry.wavy_surface(4.0, 40),
}
# Meshes whose tangent follows u; the annulus' tangent is concentric instead.
UV_ALIGNED = ["sphere", "sphere-min", "box", "wavy"]
CLOSED = ["sphere", "sphere-min", "box"]


@pytest.fixture(params=list(MESHES), ids=list(MESHES))
def mesh(request) -> Mesh:
    return MESHES[request.param]()


def _f64(mesh: Mesh):
    return (
        mesh.positions.astype(np.float64),
        mesh.normals.astype(np.float64),
        mesh.tangents.astype(np.float64),
        mesh.uvs.astype(np.float64),
        mesh.indices.astype(np.int64),
    )


def _face_cross(mesh: Mesh) -> np.ndarray:
    p, *_, idx = _f64(mesh)
    p0, p1, p2 = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
    return np.cross(p1 - p0, p2 - p0)


def assert_valid_mesh(mesh: Mesh) -> None:
    """The invariants every mesh promises, shared by the fixed and the generated cases."""
    p, n, t, uv, idx = _f64(mesh)
    count = len(p)
    assert mesh.positions.dtype == np.float32 and mesh.positions.shape == (count, 3)
    assert mesh.normals.dtype == np.float32 and mesh.normals.shape == (count, 3)
    assert mesh.tangents.dtype == np.float32 and mesh.tangents.shape == (count, 3)
    assert mesh.uvs.dtype == np.float32 and mesh.uvs.shape == (count, 2)
    assert mesh.indices.dtype == np.uint32 and mesh.indices.ndim == 2
    assert mesh.indices.shape[1] == 3 and len(mesh.indices) > 0
    for array in (p, n, t, uv):
        assert np.isfinite(array).all()
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=UNIT_TOL)
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=UNIT_TOL)
    assert np.abs(np.einsum("ij,ij->i", n, t)).max() < ORTHO_TOL
    assert idx.min() >= 0 and idx.max() < count
    assert len(np.unique(idx)) == count, "every vertex is used by some triangle"
    assert (idx[:, 0] != idx[:, 1]).all() and (idx[:, 1] != idx[:, 2]).all()
    assert (idx[:, 0] != idx[:, 2]).all()

    cross = _face_cross(mesh)
    area2 = np.linalg.norm(cross, axis=1)
    solid = area2 > 1e-9 * area2.max()
    assert solid.all(), "no zero-area triangles"
    for corner in range(3):
        facing = np.einsum("ij,ij->i", cross, n[idx[:, corner]])
        assert (facing[solid] > 0.0).all(), "counter-clockwise seen from the normal's side"


def _uv_gradients(mesh: Mesh):
    """dP/du and dP/dv of each triangle, from its edges and uv differences."""
    p, *_, uv, idx = _f64(mesh)
    e1, e2 = p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]]
    d1, d2 = uv[idx[:, 1]] - uv[idx[:, 0]], uv[idx[:, 2]] - uv[idx[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    dpdu = (e1 * d2[:, 1:] - e2 * d1[:, 1:]) / det[:, None]
    dpdv = (e2 * d1[:, :1] - e1 * d2[:, :1]) / det[:, None]
    return dpdu, dpdv, det


def _signed_volume(mesh: Mesh) -> float:
    p, *_, idx = _f64(mesh)
    return float(np.einsum("ij,ij->", p[idx[:, 0]], np.cross(p[idx[:, 1]], p[idx[:, 2]])) / 6)


# -- shared invariants ---------------------------------------------------------


def test_mesh_invariants(mesh):
    """Attributes are finite float32 of matching length, normals and tangents unit and
    perpendicular, indices uint32 in range, and every triangle is wound counter-clockwise
    seen from the side its vertex normals point to."""
    assert_valid_mesh(mesh)


def test_interleaved_layout(mesh):
    """interleaved() is (N, 11) float32: position, normal, tangent, uv in that order."""
    rows = mesh.interleaved()
    assert rows.dtype == np.float32 and rows.shape == (mesh.vertex_count, 11)
    np.testing.assert_array_equal(rows[:, 0:3], mesh.positions)
    np.testing.assert_array_equal(rows[:, 3:6], mesh.normals)
    np.testing.assert_array_equal(rows[:, 6:9], mesh.tangents)
    np.testing.assert_array_equal(rows[:, 9:11], mesh.uvs)


def test_mesh_is_frozen(mesh):
    """A mesh cannot be modified: attributes cannot be reassigned and arrays are read-only."""
    with pytest.raises(AttributeError):
        mesh.positions = mesh.positions  # type: ignore[misc]
    with pytest.raises(ValueError):
        mesh.positions[0, 0] = 1.0


def test_mesh_copies_its_inputs():
    """Constructing a Mesh leaves the caller's arrays writable and unshared."""
    positions = np.zeros((3, 3), dtype=np.float32)
    m = Mesh(
        positions,
        np.eye(3, dtype=np.float32),
        np.eye(3, dtype=np.float32)[[1, 2, 0]],
        np.zeros((3, 2), dtype=np.float32),
        np.array([[0, 1, 2]], dtype=np.uint32),
    )
    positions[0, 0] = 5.0
    assert m.positions[0, 0] == 0.0


def test_mesh_rejects_mismatched_shapes():
    """Attributes of different lengths, or of the wrong width, are refused."""
    ok3, ok2 = np.zeros((4, 3)), np.zeros((4, 2))
    tri = np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="normals"):
        Mesh(ok3, np.zeros((3, 3)), ok3, ok2, tri)
    with pytest.raises(ValueError, match="uvs"):
        Mesh(ok3, ok3, ok3, ok3, tri)


@pytest.mark.parametrize("name", UV_ALIGNED)
def test_tangent_frame_follows_uv(name):
    """Where the tangent follows u, it points along dP/du and cross(n, t) along dP/dv, so a
    green-up tangent-space normal map is applied the right way round."""
    m = MESHES[name]()
    _, n, t, _, idx = _f64(m)
    dpdu, dpdv, det = _uv_gradients(m)
    assert (det > 0).all(), "uv triangles are counter-clockwise too (no mirrored uv)"
    for corner in range(3):
        tc, nc = t[idx[:, corner]], n[idx[:, corner]]
        assert (np.einsum("ij,ij->i", tc, dpdu) > 0).all()
        assert (np.einsum("ij,ij->i", np.cross(nc, tc), dpdv) > 0).all()


@pytest.mark.parametrize("name", CLOSED)
def test_closed_meshes_enclose_positive_volume(name):
    """Closed meshes have outward winding: their signed volume is positive."""
    assert _signed_volume(MESHES[name]()) > 0.0


# -- sphere ------------------------------------------------------------------------


def test_sphere_geometry():
    """Vertices lie on the sphere, normals are radial, and the tangent points east:
    horizontal and along cross(+y, n)."""
    r = 2.5
    p, n, t, uv, _ = _f64(geometry.sphere(r, 32, 16))
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), r, rtol=1e-6)
    np.testing.assert_allclose(n, p / r, atol=1e-6)
    np.testing.assert_allclose(t[:, 1], 0.0, atol=1e-7)
    body = np.abs(n[:, 1]) < 0.999
    east = np.cross([0.0, 1.0, 0.0], n[body])
    east /= np.linalg.norm(east, axis=1, keepdims=True)
    np.testing.assert_allclose(t[body], east, atol=1e-6)
    assert uv.min() >= 0.0 and uv.max() <= 1.0


def test_sphere_counts():
    """A segments × rings sphere has one pole vertex per segment at each pole, segments + 1
    vertices (seam duplicated) on each inner parallel, and 2 · segments · (rings - 1)
    triangles."""
    s, r = 20, 9
    m = geometry.sphere(1.0, s, r)
    assert m.vertex_count == 2 * s + (r - 1) * (s + 1)
    assert m.triangle_count == 2 * s * (r - 1)


def test_sphere_volume_converges():
    """A fine sphere encloses close to 4/3 π r³, a check that no triangle is missing or flipped."""
    r = 1.3
    assert _signed_volume(geometry.sphere(r, 128, 64)) == pytest.approx(
        4 / 3 * math.pi * r**3, rel=2e-3
    )


@pytest.mark.parametrize("segments", [3, 4, 7, 64])
def test_sphere_poles_have_one_vertex_per_segment(segments):
    """Each pole has one vertex per segment, each used by exactly one triangle, each with its
    own unit tangent perpendicular to the pole normal (no shared degenerate fan)."""
    m = geometry.sphere(1.0, segments, 5)
    p, n, t, uv, idx = _f64(m)
    for sign in (1.0, -1.0):
        pole = np.flatnonzero(np.isclose(p[:, 1], sign, atol=1e-7))
        assert len(pole) == segments
        np.testing.assert_allclose(n[pole], [[0.0, sign, 0.0]] * segments, atol=1e-7)
        np.testing.assert_allclose(np.linalg.norm(t[pole], axis=1), 1.0, atol=UNIT_TOL)
        assert np.abs(t[pole] @ [0.0, 1.0, 0.0]).max() < ORTHO_TOL
        assert len(np.unique(np.round(t[pole], 5), axis=0)) == segments
        assert len(np.unique(np.round(uv[pole, 0], 6))) == segments
        uses = np.bincount(idx.ravel(), minlength=len(p))[pole]
        np.testing.assert_array_equal(uses, 1)


@settings(max_examples=40, deadline=None)
@given(
    radius=st.floats(0.01, 100.0),
    segments=st.integers(3, 96),
    rings=st.integers(2, 48),
)
def test_sphere_any_tessellation_is_valid(radius, segments, rings):
    """Any allowed radius, segment and ring count gives a valid, outward-wound sphere."""
    m = geometry.sphere(radius, segments, rings)
    assert_valid_mesh(m)
    assert _signed_volume(m) > 0.0


# -- annulus ----------------------------------------------------------------------


def test_annulus_lies_in_the_ring():
    """All vertices are at y = 0 with inner <= r <= outer, and normals are +y."""
    inner, outer = 0.4, 1.5
    p, n, *_ = _f64(geometry.annulus(inner, outer, 64, 5))
    r = np.hypot(p[:, 0], p[:, 2])
    np.testing.assert_array_equal(p[:, 1], 0.0)
    assert r.min() >= inner * (1 - 1e-6) and r.max() <= outer * (1 + 1e-6)
    np.testing.assert_array_equal(n, [[0.0, 1.0, 0.0]] * len(n))


def test_annulus_has_a_real_hole():
    """The triangles cover exactly the polygonal ring: area (s/2)·sin(2π/s)·(R² - r²), so
    nothing covers the hole and nothing overlaps."""
    inner, outer, s = 0.5, 1.2, 40
    m = geometry.annulus(inner, outer, s, 3)
    area = 0.5 * np.linalg.norm(_face_cross(m), axis=1).sum()
    expected = 0.5 * s * math.sin(2 * math.pi / s) * (outer**2 - inner**2)
    assert area == pytest.approx(expected, rel=1e-6)
    p, *_, idx = _f64(m)
    centroids = p[idx].mean(axis=1)
    assert np.hypot(centroids[:, 0], centroids[:, 2]).min() > inner * math.cos(math.pi / s)


def test_annulus_tangent_and_uv():
    """The tangent is concentric, (-z, 0, x)/r, and uv maps (x, z) from [-outer, outer] to
    [0, 1]."""
    outer = 2.0
    p, _, t, uv, _ = _f64(geometry.annulus(0.5, outer, 30, 2))
    r = np.hypot(p[:, 0], p[:, 2])
    expected = np.stack([-p[:, 2], np.zeros(len(p)), p[:, 0]], 1) / r[:, None]
    np.testing.assert_allclose(t, expected, atol=1e-6)
    np.testing.assert_allclose(uv[:, 0], (p[:, 0] + outer) / (2 * outer), atol=1e-6)
    np.testing.assert_allclose(uv[:, 1], (p[:, 2] + outer) / (2 * outer), atol=1e-6)


@settings(max_examples=40, deadline=None)
@given(
    inner=st.floats(0.01, 10.0),
    ratio=st.floats(1.01, 10.0),
    segments=st.integers(3, 300),
    rings=st.integers(1, 8),
)
def test_annulus_any_tessellation_is_valid(inner, ratio, segments, rings):
    """Any allowed ring and tessellation gives a valid mesh with no vertex inside the hole."""
    m = geometry.annulus(inner, inner * ratio, segments, rings)
    assert_valid_mesh(m)
    p = m.positions.astype(np.float64)
    assert np.hypot(p[:, 0], p[:, 2]).min() >= inner * (1 - 1e-6)


def _cover_counts(mesh: Mesh, points: np.ndarray) -> np.ndarray:
    """How many of the mesh's triangles (in the xz plane) hold each point."""
    p, *_, idx = _f64(mesh)
    a, b, c = (p[idx[:, k]][:, [0, 2]][:, None] for k in range(3))

    def side(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return (v[..., 0] - u[..., 0]) * (points[:, 1] - u[..., 1]) - (
            v[..., 1] - u[..., 1]) * (points[:, 0] - u[..., 0])

    s1, s2, s3 = side(a, b), side(b, c), side(c, a)
    return (((s1 > 0) & (s2 > 0) & (s3 > 0)) | ((s1 < 0) & (s2 < 0) & (s3 < 0))).sum(0)


def _quads_shaded(mesh: Mesh, pixels: int) -> float:
    """Seen from above at ``pixels`` across: how many times a 2×2 quad of pixels is shaded
    on average, once for every triangle covering one of its pixel centres."""
    p, *_, idx = _f64(mesh)
    q = (p[:, [0, 2]] / np.abs(p).max() + 1.0) * (pixels / 2)
    pairs, shaded = 0, set()
    for corners in q[idx]:
        lo, hi = np.floor(corners.min(0)).astype(int), np.ceil(corners.max(0)).astype(int)
        ys, xs = np.mgrid[lo[1]:hi[1] + 1, lo[0]:hi[0] + 1]
        centres = np.stack([xs.ravel() + 0.5, ys.ravel() + 0.5], -1)
        edges = []
        for k in range(3):
            (ux, uy), (vx, vy) = corners[(k + 1) % 3] - corners[k], (centres - corners[k]).T
            edges.append(ux * vy - uy * vx)
        inside = np.all(np.stack(edges) >= 0, 0) | np.all(np.stack(edges) <= 0, 0)
        quads = {(int(x) // 2, int(y) // 2) for x, y in centres[inside]}
        pairs += len(quads)
        shaded |= quads
    return pairs / len(shaded)


@pytest.mark.parametrize("segments", [40, 128, 256])
def test_annulus_covers_its_ring_once(segments):
    """Every point between the two edge polygons lies in exactly one triangle, and none in
    the hole or outside: the coarser rings inside leave no gap and no overlap."""
    inner, outer = 0.125, 1.0
    m = geometry.annulus(inner, outer, segments, 4)
    rng = np.random.default_rng(segments)
    radius = np.sqrt(rng.uniform(0.0, (1.05 * outer) ** 2, 20000))
    angle = rng.uniform(0.0, 2 * math.pi, 20000)
    points = np.stack([radius * np.cos(angle), radius * np.sin(angle)], 1)
    # The polygons' edges: a point's distance along its direction to an s-gon's boundary.
    sector = np.mod(angle, 2 * math.pi / segments) - math.pi / segments
    edge = math.cos(math.pi / segments) / np.cos(sector)
    counts = _cover_counts(m, points)
    clear = (np.abs(radius - inner * edge) > 1e-9) & (np.abs(radius - outer * edge) > 1e-9)
    within = (radius > inner * edge) & (radius < outer * edge)
    np.testing.assert_array_equal(counts[clear], within[clear].astype(int))


def test_annulus_shades_each_pixel_quad_fewer_times_than_a_uniform_grid():
    """The CD at a thumbnail's density (128 segments, 4 rings; 256 px across) as a uniform
    grid had every quad near the hole under several slivers: on average a quad was shaded
    1.65 times. The coarser rings inside bring that to 1.3."""
    cd = geometry.annulus(0.125, 1.0, 128, 4)
    radii = np.linspace(0.125, 1.0, 5)
    angles = np.arange(128) * (2 * math.pi / 128)
    rr, aa = (v.ravel() for v in np.meshgrid(radii, angles, indexing="ij"))
    flat = np.tile([0.0, 1.0, 0.0], (len(rr), 1))
    grid = make_mesh(np.stack([rr * np.cos(aa), 0 * rr, rr * np.sin(aa)], 1), flat,
                              flat[:, [1, 0, 2]], np.zeros((len(rr), 2)),
                              np.concatenate([zip_rings(128 * k, 128, 128 * (k + 1), 128)
                                              for k in range(4)]))
    assert_valid_mesh(cd)
    assert _quads_shaded(cd, 256) < 1.35 < 1.6 < _quads_shaded(grid, 256)


# -- box -----------------------------------------------------------------------------


def test_box_counts_and_bounds():
    """A box has 24 vertices and 12 triangles, and spans ±size/2 on each axis."""
    size = (1.0, 2.0, 3.0)
    m = geometry.box(size)
    assert m.vertex_count == 24 and m.triangle_count == 12
    np.testing.assert_allclose(m.positions.min(0), -np.array(size) / 2)
    np.testing.assert_allclose(m.positions.max(0), np.array(size) / 2)


def test_box_faces_are_flat():
    """Each face's four vertices share one axis-aligned normal and tangent, lie in the plane
    the normal names, and have the uv corners of the unit square; the six normals differ."""
    size = np.array([1.0, 2.0, 3.0])
    p, n, t, uv, _ = _f64(geometry.box(tuple(size)))
    face_normals = []
    for f in range(6):
        k = slice(4 * f, 4 * f + 4)
        np.testing.assert_array_equal(n[k], n[k][[0, 0, 0, 0]])
        np.testing.assert_array_equal(t[k], t[k][[0, 0, 0, 0]])
        assert np.count_nonzero(n[4 * f]) == 1
        np.testing.assert_allclose(p[k] @ n[4 * f], np.abs(n[4 * f]) @ size / 2)
        assert sorted(map(tuple, uv[k])) == [(0, 0), (0, 1), (1, 0), (1, 1)]
        face_normals.append(tuple(n[4 * f]))
    assert len(set(face_normals)) == 6


def test_box_faces_stand_upright():
    """On the four side faces v points up (+y), so a texture stands upright; on the top face
    v points to -z and on the bottom face to +z, as seen from outside with the front at +z."""
    _, n, t, _, _ = _f64(geometry.box())
    v = np.cross(n, t)
    for f in range(6):
        normal, up = n[4 * f], v[4 * f]
        if normal[1] == 0.0:
            np.testing.assert_array_equal(up, [0.0, 1.0, 0.0])
        else:
            np.testing.assert_array_equal(up, [0.0, 0.0, -normal[1]])


def test_box_volume_and_area():
    """The box's signed volume and surface area are exactly those of the size given."""
    a, b, c = 1.0, 2.0, 3.0
    m = geometry.box((a, b, c))
    assert _signed_volume(m) == pytest.approx(a * b * c)
    area = 0.5 * np.linalg.norm(_face_cross(m), axis=1).sum()
    assert area == pytest.approx(2 * (a * b + b * c + c * a))


# -- wavy surface ------------------------------------------------------------------


def _height(x, z, waves):
    """The heightfield of the brief, written independently of the module."""
    h = np.zeros_like(x)
    for amplitude, wavelength, direction, phase in waves:
        d = math.radians(direction)
        h += amplitude * np.sin(
            2 * math.pi * (x * math.cos(d) + z * math.sin(d)) / wavelength + phase
        )
    return h


def _check_wavy(size, resolution, waves):
    m = geometry.wavy_surface(size, resolution, waves)
    p, n, t, uv, _ = _f64(m)
    x, z = p[:, 0], p[:, 2]
    np.testing.assert_allclose(p[:, 1], _height(x, z, waves), atol=1e-5 * (1 + size))
    eps = 1e-5 * size
    hx = (_height(x + eps, z, waves) - _height(x - eps, z, waves)) / (2 * eps)
    hz = (_height(x, z + eps, waves) - _height(x, z - eps, waves)) / (2 * eps)
    # The surface normal is ∂P/∂z × ∂P/∂x with P = (x, h, z); the tangent is ∂P/∂x.
    fd_normal = np.cross(np.stack([0 * x, hz, 1 + 0 * x], 1), np.stack([1 + 0 * x, hx, 0 * x], 1))
    fd_normal /= np.linalg.norm(fd_normal, axis=1, keepdims=True)
    fd_tangent = np.stack([1 + 0 * x, hx, 0 * x], 1)
    fd_tangent /= np.linalg.norm(fd_tangent, axis=1, keepdims=True)
    np.testing.assert_allclose(n, fd_normal, atol=2e-5)
    np.testing.assert_allclose(t, fd_tangent, atol=2e-5)
    return m


def test_wavy_normals_match_finite_differences():
    """Heights follow the sum of sines, and normals and tangents equal those of the height
    function by central differences."""
    _check_wavy(4.0, 64, list(geometry.DEFAULT_WAVES))


def test_wavy_grid_and_uv():
    """resolution is vertices per side, covering ±size/2 in x and z; u follows +x from 0 and
    v follows -z from 0."""
    size, res = 3.0, 17
    m = geometry.wavy_surface(size, res)
    p, _, _, uv, _ = _f64(m)
    assert m.vertex_count == res * res and m.triangle_count == 2 * (res - 1) ** 2
    for axis in (0, 2):
        assert p[:, axis].min() == pytest.approx(-size / 2)
        assert p[:, axis].max() == pytest.approx(size / 2)
    np.testing.assert_allclose(uv[:, 0], p[:, 0] / size + 0.5, atol=1e-6)
    np.testing.assert_allclose(uv[:, 1], 0.5 - p[:, 2] / size, atol=1e-6)


def test_wavy_defaults_are_gentle():
    """The default oil-slick waves are a few, gentle ones: 3-4 waves, slopes below 0.5."""
    assert 3 <= len(geometry.DEFAULT_WAVES) <= 4
    n = geometry.wavy_surface().normals
    assert n[:, 1].min() > 1 / math.sqrt(1 + 0.5**2)
    assert n[:, 1].min() < 0.999, "the surface is not flat"


def test_wavy_without_waves_is_flat():
    """With no waves the surface is the plane y = 0 facing +y, tangent +x."""
    m = geometry.wavy_surface(2.0, 5, [])
    np.testing.assert_array_equal(m.positions[:, 1], 0.0)
    np.testing.assert_array_equal(m.normals, [[0, 1, 0]] * 25)
    np.testing.assert_array_equal(m.tangents, [[1, 0, 0]] * 25)


wave = st.tuples(
    st.floats(-0.05, 0.05),
    st.floats(0.5, 5.0),
    st.floats(-360.0, 360.0),
    st.floats(-10.0, 10.0),
)


@settings(max_examples=30, deadline=None)
@given(waves=st.lists(wave, max_size=4), resolution=st.integers(2, 40))
def test_wavy_any_waves(waves, resolution):
    """Any gentle wave list gives a valid mesh whose normals match finite differences."""
    m = _check_wavy(4.0, resolution, waves)
    assert_valid_mesh(m)


# -- build ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "args", "direct"),
    [
        ("sphere", {"radius": 2.0, "segments": 8, "rings": 4}, lambda: geometry.sphere(2.0, 8, 4)),
        ("annulus", {"inner_radius": 0.2, "outer_radius": 1.0}, lambda: geometry.annulus(0.2, 1)),
        ("box", {"size": [1, 2, 3]}, lambda: geometry.box((1, 2, 3))),
        ("wavy", {"resolution": 8}, lambda: geometry.wavy_surface(resolution=8)),
        ("sphere", {}, geometry.sphere),
    ],
)
def test_build_dispatches(kind, args, direct):
    """build(kind, **args) gives the same mesh as calling the function directly."""
    a, b = geometry.build(kind, **args), direct()
    np.testing.assert_array_equal(a.interleaved(), b.interleaved())
    np.testing.assert_array_equal(a.indices, b.indices)


def test_build_unknown_kind():
    """An unknown geometry is a ValueError naming it and the known kinds."""
    with pytest.raises(ValueError, match=r"unknown geometry 'torus' \(known: sphere, annulus"):
        geometry.build("torus")


def test_build_unknown_argument_message():
    """An unknown argument is a ValueError naming the geometry, the argument and the known ones."""
    with pytest.raises(ValueError) as info:
        geometry.build("annulus", radius=1.0)
    assert str(info.value) == (
        "geometry 'annulus': unknown argument 'radius' "
        "(known: inner_radius, outer_radius, segments, rings)"
    )


@pytest.mark.parametrize(
    ("kind", "args", "bad"),
    [
        ("sphere", {"radius": 0}, "radius"),
        ("sphere", {"radius": -1.0}, "radius"),
        ("sphere", {"radius": float("nan")}, "radius"),
        ("sphere", {"radius": float("inf")}, "radius"),
        ("sphere", {"radius": "1"}, "radius"),
        ("sphere", {"segments": 2}, "segments"),
        ("sphere", {"segments": 4097}, "segments"),
        ("sphere", {"segments": 8.0}, "segments"),
        ("sphere", {"segments": True}, "segments"),
        ("sphere", {"rings": 1}, "rings"),
        ("annulus", {"inner_radius": 1.0, "outer_radius": 1.0}, "inner_radius"),
        ("annulus", {"inner_radius": 2.0, "outer_radius": 1.0}, "inner_radius"),
        ("annulus", {"inner_radius": 0.0, "outer_radius": 1.0}, "inner_radius"),
        ("annulus", {"inner_radius": 0.5, "outer_radius": -1.0}, "outer_radius"),
        ("annulus", {"inner_radius": 0.5}, "outer_radius"),
        ("annulus", {"inner_radius": 0.5, "outer_radius": 1.0, "segments": 5000}, "segments"),
        ("annulus", {"inner_radius": 0.5, "outer_radius": 1.0, "rings": 0}, "rings"),
        ("box", {"size": (1.0, 0.0, 1.0)}, "size"),
        ("box", {"size": (1.0, 1.0)}, "size"),
        ("box", {"size": 2.0}, "size"),
        ("box", {"size": "abc"}, "size"),
        ("wavy", {"size": 0.0}, "size"),
        ("wavy", {"resolution": 1}, "resolution"),
        ("wavy", {"resolution": 2049}, "resolution"),
        ("wavy", {"waves": [(0.1, 0.0, 0.0, 0.0)]}, "waves[0]"),
        ("wavy", {"waves": [(0.1, 1.0, 0.0)]}, "waves[0]"),
        ("wavy", {"waves": [(0.1, 1.0, 0.0, float("nan"))]}, "waves[0]"),
        ("wavy", {"waves": "big"}, "waves"),
    ],
)
def test_build_invalid_argument_names_it(kind, args, bad):
    """An out-of-range or ill-typed argument is a ValueError naming the geometry and argument."""
    with pytest.raises(ValueError) as info:
        geometry.build(kind, **args)
    message = str(info.value)
    assert message.startswith(f"geometry '{kind}': ")
    assert f"'{bad}'" in message


def test_direct_calls_validate_too():
    """The functions check their arguments themselves, not only through build()."""
    with pytest.raises(ValueError, match="'segments'"):
        geometry.sphere(segments=1)
    with pytest.raises(ValueError, match="'resolution'"):
        geometry.wavy_surface(resolution=0)
