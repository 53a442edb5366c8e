"""Procedural meshes for the headless renderer.

Every mesh carries a unit tangent per vertex because the iridescent MDFs are
anisotropic: the highlight's shape follows the tangent, so a tangent that is
zero, NaN or flips between neighbouring vertices shows up as a visible seam.

Conventions shared by all meshes, relied on by ``glsl/surface.glsl``:

* y is up; triangles are counter-clockwise seen from the side the normals
  point to, so back-face culling and the normals agree.
* The shader's frame is ``(t, cross(n, t), n)``. Wherever the tangent follows
  ``u`` (sphere, box, wavy surface), ``cross(n, t)`` points along increasing
  ``v``, so a tangent-space normal map with "green up" (OpenGL convention) is
  applied the right way round. The annulus' tangent is concentric instead, as
  the paper's CD needs, and its ``uv`` is a plain planar projection.
* Math is done in float64 and rounded once, to float32, at the end.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from opaline.scene import generators

TWO_PI = 2.0 * math.pi

SEGMENTS = (3, 4096)
RINGS = (1, 4096)
RESOLUTION = (2, 2048)

# Gentle, mutually oblique swells: at most ~0.35 of slope together, so an oil
# slick's thin-film colours shift across the surface without it looking stormy.
# (amplitude, wavelength, direction in degrees, phase in radians)
DEFAULT_WAVES: tuple[tuple[float, float, float, float], ...] = (
    (0.030, 2.10, 15.0, 0.0),
    (0.018, 1.30, 70.0, 1.3),
    (0.010, 0.73, 135.0, 2.1),
    (0.005, 0.41, 205.0, 0.7),
)


@dataclass(frozen=True, eq=False)
class Mesh:
    """Vertex attributes and triangles, in the layout the renderer uploads.

    ``eq=False`` because element-wise array comparison has no single truth
    value; the arrays are made read-only so that ``frozen`` really holds.
    """

    positions: np.ndarray  # (N, 3) float32
    normals: np.ndarray  # (N, 3) float32, unit
    tangents: np.ndarray  # (N, 3) float32, unit, perpendicular to the normal
    uvs: np.ndarray  # (N, 2) float32
    indices: np.ndarray  # (M, 3) uint32, counter-clockwise seen from the normal's side

    def __post_init__(self) -> None:
        n = None
        for name, width, dtype in (
            ("positions", 3, np.float32),
            ("normals", 3, np.float32),
            ("tangents", 3, np.float32),
            ("uvs", 2, np.float32),
            ("indices", 3, np.uint32),
        ):
            # A private copy: freezing must not make the caller's array read-only.
            array = np.array(getattr(self, name), dtype=dtype, order="C")
            if array.ndim != 2 or array.shape[1] != width:
                raise ValueError(f"Mesh.{name} must have shape (*, {width}), got {array.shape}")
            if name != "indices":
                if n is not None and len(array) != n:
                    raise ValueError(f"Mesh.{name} has {len(array)} rows, positions have {n}")
                n = len(array)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @property
    def vertex_count(self) -> int:
        return len(self.positions)

    @property
    def triangle_count(self) -> int:
        return len(self.indices)

    def interleaved(self) -> np.ndarray:
        """(N, 11) float32 rows for a single VBO laid out as ``3f 3f 3f 2f``.

        One buffer with one stride keeps the vertex array setup to one line
        and the attributes of a vertex in the same cache line.
        """
        return np.concatenate([self.positions, self.normals, self.tangents, self.uvs], axis=1)


def _mesh(positions, normals, tangents, uvs, indices) -> Mesh:
    """Normalise in float64 before rounding, so float32 vectors are unit to ~1e-7."""
    normals = _unit(normals)
    tangents = _unit(tangents)
    return Mesh(
        positions=np.asarray(positions, dtype=np.float32),
        normals=normals.astype(np.float32),
        tangents=tangents.astype(np.float32),
        uvs=np.asarray(uvs, dtype=np.float32),
        indices=np.asarray(indices, dtype=np.uint32),
    )


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _grid_indices(rows: int, cols: int) -> np.ndarray:
    """Two triangles per cell of a row-major ``rows × cols`` vertex grid.

    For vertices ``a=(i, j)``, ``b=(i, j+1)``, ``c=(i+1, j)``, ``d=(i+1, j+1)``
    the triangles are ``(a, b, c)`` and ``(b, d, c)``: counter-clockwise seen
    from the side of ``(b - a) × (c - a)``. Where that points away from the
    normal, callers swap the last two corners.
    """
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    a = (i * cols + j).ravel()
    b, c = a + 1, a + cols
    d = c + 1
    return np.concatenate([np.stack([a, b, c], 1), np.stack([b, d, c], 1)]).reshape(-1, 3)


# -- argument checks ---------------------------------------------------------


def _positive(name: str, value) -> float:
    value = generators.real(name, value)
    if value <= 0.0:
        raise ValueError(f"argument '{name}' must be > 0, got {value}")
    return value


def _sequence(name: str, value, length: int) -> Sequence:
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise ValueError(f"argument '{name}' must be a sequence of {length} numbers, got {value!r}")
    if len(value) != length:
        raise ValueError(f"argument '{name}' must have {length} entries, got {len(value)}")
    return value


# -- meshes ------------------------------------------------------------------


def sphere(radius: float = 1.0, segments: int = 128, rings: int = 64) -> Mesh:
    """UV sphere whose tangent follows the parallels, pole vertices included.

    The tangent is dP/d(longitude), which vanishes at the poles; using each
    pole vertex's own longitude instead keeps it defined there. So every pole
    triangle gets its own pole vertex, at the longitude of the middle of its
    wedge: the anisotropic highlight stays well defined at the poles and the
    texture is not pinched into one texel-wide fan. ``u`` runs east (to the
    right seen from outside, north up), ``v`` north, seam duplicated at u=0/1.
    """
    radius = _positive("radius", radius)
    segments = generators.integer("segments", segments, *SEGMENTS)
    rings = generators.integer("rings", rings, 2, RINGS[1])

    # Body rows (excluding the poles): rings-1 parallels of segments+1 vertices.
    theta = np.linspace(0.0, math.pi, rings + 1)[1:-1]
    phi_body = np.linspace(0.0, TWO_PI, segments + 1)
    phi_pole = (np.arange(segments) + 0.5) * (TWO_PI / segments)

    th, ph = np.meshgrid(theta, phi_body, indexing="ij")
    th = np.concatenate([np.zeros(segments), th.ravel(), np.full(segments, math.pi)])
    ph = np.concatenate([phi_pole, ph.ravel(), phi_pole])

    # East = right-handed rotation about +y = from +x toward -z.
    normals = np.stack([np.sin(th) * np.cos(ph), np.cos(th), -np.sin(th) * np.sin(ph)], 1)
    tangents = np.stack([-np.sin(ph), np.zeros_like(ph), -np.cos(ph)], 1)
    uvs = np.stack([ph / TWO_PI, 1.0 - th / math.pi], 1)
    # The exact poles, not sin(0) and cos(π) rounding noise.
    normals[:segments] = (0.0, 1.0, 0.0)
    normals[-segments:] = (0.0, -1.0, 0.0)

    cols = segments + 1
    first = segments  # index of body vertex (row 0, column 0)
    last_row = first + (rings - 2) * cols
    south = first + (rings - 1) * cols
    j = np.arange(segments)
    # The grid (row i = colatitude, column j = longitude) has (b-a)×(c-a) =
    # east × south = inward, so every triangle swaps its last two corners.
    body = first + _grid_indices(rings - 1, cols)[:, [0, 2, 1]]
    north_fan = np.stack([j, first + j, first + j + 1], 1)
    south_fan = np.stack([last_row + j, south + j, last_row + j + 1], 1)
    indices = np.concatenate([north_fan, body, south_fan])
    return _mesh(normals * radius, normals, tangents, uvs, indices)


def annulus(inner_radius: float, outer_radius: float, segments: int = 256, rings: int = 4) -> Mesh:
    """Flat ring in the xz plane facing +y, the disc of the paper's CD figure.

    The hole is real (no triangles inside ``inner_radius``) so nothing is shaded
    where a CD has none. The tangent is concentric, ``(-z, 0, x) / r``, because
    the grooves run along the tracks; ``uv`` is the planar projection of
    ``(x, z)`` from ``[-outer, outer]`` onto ``[0, 1]``.
    """
    inner = _positive("inner_radius", inner_radius)
    outer = _positive("outer_radius", outer_radius)
    if inner >= outer:
        raise ValueError(f"argument 'inner_radius' must be < outer_radius ({outer}), got {inner}")
    segments = generators.integer("segments", segments, *SEGMENTS)
    rings = generators.integer("rings", rings, *RINGS)

    # Angular columns wrap around: the uv is planar, so no seam vertex is needed.
    r = np.linspace(inner, outer, rings + 1)
    alpha = np.arange(segments) * (TWO_PI / segments)
    rr, aa = np.meshgrid(r, alpha, indexing="ij")
    rr, aa = rr.ravel(), aa.ravel()
    x, z = rr * np.cos(aa), rr * np.sin(aa)
    zeros = np.zeros_like(x)

    positions = np.stack([x, zeros, z], 1)
    normals = np.stack([zeros, np.ones_like(x), zeros], 1)
    tangents = np.stack([-z, zeros, x], 1) / rr[:, None]
    uvs = np.stack([(x / outer + 1.0) * 0.5, (z / outer + 1.0) * 0.5], 1)

    # Row i = radius, column j = angle: (b-a)×(c-a) = (angle direction) × (radial
    # direction) = +y, so (a, b, c) and (b, d, c) are counter-clockwise from +y.
    i, j = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    i, j = i.ravel(), j.ravel()
    jn = (j + 1) % segments
    a, b = i * segments + j, i * segments + jn
    c, d = a + segments, b + segments
    indices = np.concatenate([np.stack([a, b, c], 1), np.stack([b, d, c], 1)])
    return _mesh(positions, normals, tangents, uvs, indices)


# (normal, tangent = u direction); the bitangent cross(n, t) is the v direction.
# Side faces have v up; the top face is seen with -z up, the bottom with +z up.
_BOX_FACES = (
    ((1, 0, 0), (0, 0, -1)),
    ((-1, 0, 0), (0, 0, 1)),
    ((0, 1, 0), (1, 0, 0)),
    ((0, -1, 0), (1, 0, 0)),
    ((0, 0, 1), (1, 0, 0)),
    ((0, 0, -1), (-1, 0, 0)),
)


def box(size: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> Mesh:
    """Axis-aligned box centred at the origin, unshared corners per face.

    Four vertices per face keep the normals flat, so each face reflects as one
    mirror-like patch, and give each face its own full [0, 1] uv square so a
    normal map (the paper's perturbed cube) covers every face the same way.
    """
    size = _sequence("size", size, 3)
    half = np.array([_positive("size", s) for s in size]) * 0.5

    corners = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)], dtype=np.float64)
    positions, normals, tangents, uvs, indices = [], [], [], [], []
    for face, (n, t) in enumerate(_BOX_FACES):
        n, t = np.array(n, dtype=np.float64), np.array(t, dtype=np.float64)
        b = np.cross(n, t)
        for su, sv in corners:
            positions.append(half * (n + su * t + sv * b))
        normals += [n] * 4
        tangents += [t] * 4
        uvs += list((corners + 1.0) * 0.5)
        k = 4 * face
        # (t, t+b) from the first corner: t × b = n, counter-clockwise from outside.
        indices += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
    return _mesh(positions, normals, tangents, uvs, indices)


def _check_waves(waves) -> np.ndarray:
    """(K, 4) float64 rows of amplitude, wavelength, direction (deg), phase."""
    if isinstance(waves, str | bytes) or not isinstance(waves, Sequence | np.ndarray):
        raise ValueError(f"argument 'waves' must be a list of 4-tuples, got {waves!r}")
    rows = []
    for k, wave in enumerate(waves):
        wave = _sequence(f"waves[{k}]", wave, 4)
        amplitude, wavelength, direction, phase = (generators.real(f"waves[{k}]", v) for v in wave)
        if wavelength <= 0.0:
            raise ValueError(f"argument 'waves[{k}]' needs a wavelength > 0, got {wavelength}")
        rows.append((amplitude, wavelength, direction, phase))
    return np.array(rows, dtype=np.float64).reshape(-1, 4)


def wave_height(x, z, waves=DEFAULT_WAVES):
    """Height and its gradient ``(h, dh/dx, dh/dz)`` of the wavy surface.

    Public so that tests and other code (e.g. a reference ray caster) can use
    the same surface the mesh samples, in float64.
    """
    w = _check_waves(waves)
    x = np.asarray(x, dtype=np.float64)[..., None]
    z = np.asarray(z, dtype=np.float64)[..., None]
    amplitude, wavelength, direction, phase = w.T
    k = TWO_PI / wavelength
    dx, dz = np.cos(np.radians(direction)), np.sin(np.radians(direction))
    arg = k * (x * dx + z * dz) + phase
    slope = amplitude * k * np.cos(arg)
    return (
        (amplitude * np.sin(arg)).sum(-1),
        (slope * dx).sum(-1),
        (slope * dz).sum(-1),
    )


def wavy_surface(
    size: float = 4.0,
    resolution: int = 192,
    waves: Sequence[tuple[float, float, float, float]] = DEFAULT_WAVES,
) -> Mesh:
    """Sum-of-sines heightfield, a liquid surface for an oil-slick material.

    ``resolution`` is the number of vertices along each side. Normals come from
    the analytic gradient rather than from the triangles, so the shading stays
    smooth at any resolution; the tangent is dP/dx, which keeps the anisotropy
    aligned with x as the surface rolls. ``u`` follows +x and ``v`` follows -z
    (the top face of a box seen from above), so ``cross(n, t)`` is along +v.
    """
    size = _positive("size", size)
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    waves = _check_waves(waves)

    s = np.linspace(-0.5 * size, 0.5 * size, resolution)
    z, x = np.meshgrid(s, s, indexing="ij")  # row i = z, column j = x
    x, z = x.ravel(), z.ravel()
    h, hx, hz = wave_height(x, z, waves)

    positions = np.stack([x, h, z], 1)
    normals = np.stack([-hx, np.ones_like(x), -hz], 1)
    tangents = np.stack([np.ones_like(x), hx, np.zeros_like(x)], 1)
    uvs = np.stack([x / size + 0.5, 0.5 - z / size], 1)
    # Grid (b-a)×(c-a) = x × z = -y, so swap b and c to face +y.
    indices = _grid_indices(resolution, resolution)[:, [0, 2, 1]]
    return _mesh(positions, normals, tangents, uvs, indices)


# -- dispatch ----------------------------------------------------------------

KINDS: dict[str, Callable[..., Mesh]] = {
    "sphere": sphere,
    "annulus": annulus,
    "box": box,
    "wavy": wavy_surface,
}


def build(kind: str, **args) -> Mesh:
    """Make a mesh from a name and keyword arguments, as requests spell them.

    Requests and preset files are untrusted text, so every failure is a
    ``ValueError`` naming the geometry and the argument, which the HTTP layer
    can pass on verbatim.
    """
    return generators.call("geometry", KINDS, kind, args)
