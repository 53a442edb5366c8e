"""Procedural meshes for the headless renderer, named in presets by ``kind``.

The mesh type and its conventions (y up, counter-clockwise triangles, the
``(t, cross(n, t), n)`` frame) are in ``opaline.scene.mesh``; the wavy liquid
surface is in ``opaline.scene.waves``. This module keeps the solid shapes and
the dispatch from a preset's name to a generator.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np

from opaline.scene import generators
from opaline.scene.mesh import Mesh, grid_indices, make_mesh
from opaline.scene.rings import ring_plan, zip_rings
from opaline.scene.waves import DEFAULT_WAVES, RESOLUTION, wave_height, wavy_surface

__all__ = ["DEFAULT_WAVES", "KINDS", "Mesh", "RESOLUTION", "annulus", "arguments", "box",
           "build", "sphere",
           "wave_height", "wavy_surface"]

TWO_PI = 2.0 * math.pi

SEGMENTS = (3, 4096)
RINGS = (1, 4096)


def sphere(radius: float = 1.0, segments: int = 128, rings: int = 64) -> Mesh:
    """UV sphere whose tangent follows the parallels, pole vertices included.

    The tangent is dP/d(longitude), which vanishes at the poles; using each
    pole vertex's own longitude instead keeps it defined there. So every pole
    triangle gets its own pole vertex, at the longitude of the middle of its
    wedge: the anisotropic highlight stays well defined at the poles and the
    texture is not pinched into one texel-wide fan. ``u`` runs east (to the
    right seen from outside, north up), ``v`` north, seam duplicated at u=0/1.
    """
    radius = generators.positive("radius", radius)
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
    body = first + grid_indices(rings - 1, cols)[:, [0, 2, 1]]
    north_fan = np.stack([j, first + j, first + j + 1], 1)
    south_fan = np.stack([last_row + j, south + j, last_row + j + 1], 1)
    indices = np.concatenate([north_fan, body, south_fan])
    return make_mesh(normals * radius, normals, tangents, uvs, indices)


def annulus(inner_radius: float, outer_radius: float, segments: int = 256, rings: int = 4) -> Mesh:
    """Flat ring in the xz plane facing +y, the disc of the paper's CD figure.

    The hole is real (no triangles inside ``inner_radius``) so nothing is shaded
    where a CD has none. Both edges are polygons of ``segments`` vertices; inside,
    the rings are coarser (``scene.rings``: a uniform grid's slivers made the
    rasteriser shade the same pixels several times), with ``rings`` bands over the
    middle. The tangent is concentric, ``(-z, 0, x) / r``, because
    the grooves run along the tracks; ``uv`` is the planar projection of
    ``(x, z)`` from ``[-outer, outer]`` onto ``[0, 1]``.
    """
    inner = generators.positive("inner_radius", inner_radius)
    outer = generators.positive("outer_radius", outer_radius)
    if inner >= outer:
        raise ValueError(f"argument 'inner_radius' must be < outer_radius ({outer}), got {inner}")
    segments = generators.integer("segments", segments, *SEGMENTS)
    rings = generators.integer("rings", rings, *RINGS)

    # Every ring starts at angle 0; the uv is planar, so no seam vertex is needed.
    plan = ring_plan(inner, outer, segments, rings)
    counts = np.array([count for _, count in plan])
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rr = np.repeat([radius for radius, _ in plan], counts)
    aa = np.concatenate([np.arange(count) * (TWO_PI / count) for count in counts])
    x, z = rr * np.cos(aa), rr * np.sin(aa)
    zeros = np.zeros_like(x)

    positions = np.stack([x, zeros, z], 1)
    normals = np.stack([zeros, np.ones_like(x), zeros], 1)
    tangents = np.stack([-z, zeros, x], 1) / rr[:, None]
    uvs = np.stack([(x / outer + 1.0) * 0.5, (z / outer + 1.0) * 0.5], 1)
    indices = np.concatenate([zip_rings(int(starts[k]), int(counts[k]), int(starts[k + 1]),
                                        int(counts[k + 1])) for k in range(len(plan) - 1)])
    return make_mesh(positions, normals, tangents, uvs, indices)


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
    sides = generators.sequence("size", size, 3)
    half = np.array([generators.positive("size", s) for s in sides]) * 0.5

    corners = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)], dtype=np.float64)
    positions, normals, tangents, uvs, indices = [], [], [], [], []
    for face, (normal, tangent) in enumerate(_BOX_FACES):
        n, t = np.array(normal, dtype=np.float64), np.array(tangent, dtype=np.float64)
        b = np.cross(n, t)
        for su, sv in corners:
            positions.append(half * (n + su * t + sv * b))
        normals += [n] * 4
        tangents += [t] * 4
        uvs += list((corners + 1.0) * 0.5)
        k = 4 * face
        # (t, t+b) from the first corner: t × b = n, counter-clockwise from outside.
        indices += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
    return make_mesh(positions, normals, tangents, uvs, indices)


# -- dispatch ----------------------------------------------------------------

KINDS: dict[str, Callable[..., Mesh]] = {
    "sphere": sphere,
    "annulus": annulus,
    "box": box,
    "wavy": wavy_surface,
}


def build(kind: str, **args: Any) -> Mesh:
    """Make a mesh from a name and keyword arguments, as requests spell them.

    Requests and preset files are untrusted text, so every failure is a
    ``ValueError`` naming the geometry and the argument, which the HTTP layer
    can pass on verbatim.
    """
    return generators.call("geometry", KINDS, kind, args)


@cache
def _parameters(kind: str) -> tuple[inspect.Parameter, ...]:
    factory = KINDS.get(kind)
    return tuple(inspect.signature(factory).parameters.values()) if factory else ()


def arguments(kind: str, args: dict[str, Any]) -> dict[str, Any]:
    """``args`` with the generator's defaults filled in, as ``build`` would call it (empty
    for a kind that is not a generator here, such as a user's mesh file)."""
    return {p.name: args.get(p.name, p.default) for p in _parameters(kind)
            if p.name in args or p.default is not inspect.Parameter.empty}
