"""Whether a mesh is a closed, consistently wound surface: one whose back faces nobody
outside it can see (opaline.gl.culling).

Generators and mesh files duplicate vertices along seams and at poles (each copy with
its own normal or UV), so the topology is that of the mesh with coincident positions
welded. Every test here is conservative: a mesh it cannot prove closed is "open".
"""

from __future__ import annotations

import numpy as np

# Positions are welded on a grid of 2^-20 of the mesh's extent: far finer than any
# triangle a renderer is given, far coarser than float rounding along a seam.
WELD_STEPS = float(2**20)
# Larger meshes are not checked (and so drawn two-sided): the check holds 200-270 bytes
# a triangle at its peak (under 55 MB here), and at that size a draw's cost is its
# triangles more than its fragments.
MAX_TRIANGLES = 200_000


def referenced(positions: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Only the vertices some triangle uses (a file may carry any number of others), as
    float64, and the triangles renumbered to them."""
    indices = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    used = np.zeros(len(positions), dtype=bool)
    used[indices.ravel()] = True
    ids = np.flatnonzero(used)
    points = np.asarray(positions)[ids].astype(np.float64)
    return points, np.searchsorted(ids, indices)


def _welded(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles over welded vertex ids without those that collapse to a line or point,
    and which of ``triangles`` they are."""
    extent = float(np.ptp(points, axis=0).max())
    if not np.isfinite(extent) or extent <= 0.0:
        return np.empty((0, 3), dtype=np.int64), np.zeros(len(triangles), dtype=bool)
    # One integer per grid point (21 bits an axis, an axis at a time), equal keys one id.
    # (Not np.unique: without return_inverse it asks numpy.ma, whose import is 11 ms of a
    # cold render; tests/test_cold_start.py keeps it out.)
    keys = np.zeros(len(points), dtype=np.int64)
    for axis in range(3):
        column = points[:, axis] - points[:, axis].min()
        keys = (keys << 21) | np.round(column * (WELD_STEPS / extent)).astype(np.int64)
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]
    weld = np.empty(len(keys), dtype=np.int64)
    weld[order] = np.cumsum(np.r_[True, ordered[1:] != ordered[:-1]]) - 1
    welded = weld[triangles]
    a, b, c = welded.T
    kept = (a != b) & (b != c) & (c != a)
    return welded[kept], kept


def orientation(positions: np.ndarray, indices: np.ndarray) -> int:
    """+1: closed, consistently wound, counter-clockwise seen from outside; -1: the same
    wound clockwise; 0: open, non-manifold, inconsistently wound, a part without volume
    or wound the other way from the rest, or over ``MAX_TRIANGLES``.

    Closed and consistent means every directed edge occurs exactly once and so does its
    reverse: each edge is shared by two triangles that traverse it in opposite senses.
    That holds part by part (parts joined across edges: two spheres touching at a pole
    are two), so each part's signed volume is checked too: a part turned inside out (a
    bad export) would otherwise have its near side culled.
    """
    if not 4 <= len(indices) <= MAX_TRIANGLES:
        return 0
    points, renumbered = referenced(positions, indices)
    triangles, kept = _welded(points, renumbered)
    count = len(triangles)
    if count < 4:
        return 0
    n = int(triangles.max()) + 1
    a, b, c = triangles.T
    # Edge k of triangle t sits at k·count + t; each as one integer.
    forward = np.concatenate([a * n + b, b * n + c, c * n + a])
    order = np.argsort(forward, kind="stable")
    forward = forward[order]
    if np.any(forward[1:] == forward[:-1]):
        return 0
    backward = np.concatenate([b * n + a, c * n + b, a * n + c])
    where = np.searchsorted(forward, backward)
    np.minimum(where, len(forward) - 1, out=where)
    if not np.array_equal(forward[where], backward):
        return 0  # an edge without its reverse
    del forward, backward
    # Across each edge, the triangle that holds its reverse; each pair once.
    neighbour = (order[where] % count).astype(np.int32)
    del order, where
    owner = np.tile(np.arange(count, dtype=np.int32), 3)
    once = owner < neighbour
    part = _parts(owner[once], neighbour[once], count)
    del owner, neighbour, once
    volumes = np.bincount(part, weights=_triple_products(points, renumbered[kept]))
    volumes = volumes[np.bincount(part) > 0]
    scale = float(np.ptp(points, axis=0).max()) ** 3
    if np.all(volumes > 1e-9 * scale):
        return 1
    if np.all(volumes < -1e-9 * scale):
        return -1
    return 0


def _parts(u: np.ndarray, v: np.ndarray, count: int) -> np.ndarray:
    """Each id's connected part under the pairs (u, v), as the smallest id in it: roots
    hooked to the smallest neighbouring root, then paths halved to the roots, until no
    pair joins two parts."""
    parent = np.arange(count, dtype=np.int32)
    while True:
        pu, pv = parent[u], parent[v]
        joins = pu != pv
        if not joins.any():
            return parent
        np.minimum.at(parent, np.maximum(pu, pv)[joins], np.minimum(pu, pv)[joins])
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand


def _triple_products(points: np.ndarray, triangles: np.ndarray,
                     chunk: int = 1 << 16) -> np.ndarray:
    """a·(b×c) per triangle (six times its signed volume from the origin), in chunks."""
    out = np.empty(len(triangles))
    for start in range(0, len(triangles), chunk):
        a, b, c = (points[triangles[start:start + chunk, k]] for k in range(3))
        out[start:start + chunk] = np.einsum("ij,ij->i", a, np.cross(b, c))
    return out
