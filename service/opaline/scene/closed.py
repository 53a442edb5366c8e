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
# Larger meshes are not checked (and so drawn two-sided): the check holds ~110 bytes a
# triangle at its peak (55 MB here), and at that size a draw's cost is its triangles
# more than its fragments.
MAX_TRIANGLES = 500_000


def _welded_triangles(positions: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles over welded vertex ids without those that collapse to a line or point,
    and which of the given triangles they are."""
    positions = np.asarray(positions, dtype=np.float64)
    indices = np.asarray(indices).reshape(-1, 3)
    extent = float(np.ptp(positions, axis=0).max()) if len(positions) else 0.0
    if not np.isfinite(extent) or extent <= 0.0:
        return np.empty((0, 3), dtype=np.int32), np.zeros(len(indices), dtype=bool)
    grid = np.round((positions - positions.min(axis=0)) * (WELD_STEPS / extent)).astype(np.int64)
    # One integer per grid point (21 bits an axis): a 1-D unique is far faster than rows'.
    keys = (grid[:, 0] << 42) | (grid[:, 1] << 21) | grid[:, 2]
    # Equal keys, one id. (Not np.unique: without return_inverse it asks numpy.ma, whose
    # import is 11 ms of a cold render; tests/test_cold_start.py keeps it out.)
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]
    weld = np.empty(len(keys), dtype=np.int32)
    weld[order] = np.cumsum(np.r_[True, ordered[1:] != ordered[:-1]]) - 1
    triangles = weld[indices]
    a, b, c = triangles.T
    kept = (a != b) & (b != c) & (c != a)
    return triangles[kept], kept


def orientation(positions: np.ndarray, indices: np.ndarray) -> int:
    """+1: closed, consistently wound, counter-clockwise seen from outside; -1: the same
    wound clockwise; 0: open, non-manifold, inconsistently wound, a part without volume
    or wound the other way from the rest, or over ``MAX_TRIANGLES``.

    Closed and consistent means every directed edge occurs exactly once and so does its
    reverse: each edge is shared by two triangles that traverse it in opposite senses.
    That holds part by part, so each connected part's signed volume is checked too: a
    part turned inside out (a bad export) would otherwise have its near side culled.
    """
    if len(indices) > MAX_TRIANGLES:
        return 0
    triangles, kept = _welded_triangles(positions, indices)
    if len(triangles) < 4:
        return 0
    count = int(triangles.max()) + 1
    a, b, c = (column.astype(np.int64) for column in triangles.T)
    # Each directed edge as one integer, sorted in place.
    forward = np.concatenate([a * count + b, b * count + c, c * count + a])
    forward.sort()
    if np.any(forward[1:] == forward[:-1]):
        return 0
    backward = np.concatenate([b * count + a, c * count + b, a * count + c])
    backward.sort()
    if not np.array_equal(forward, backward):
        return 0
    del a, b, c, forward, backward
    part = _parts(triangles, count)[triangles[:, 0]]
    corners = np.asarray(indices).reshape(-1, 3)[kept]
    volumes = np.bincount(part, weights=_triple_products(np.asarray(positions, np.float64),
                                                         corners))[np.bincount(part) > 0]
    scale = float(np.ptp(np.asarray(positions, dtype=np.float64), axis=0).max()) ** 3
    if np.all(volumes > 1e-9 * scale):
        return 1
    if np.all(volumes < -1e-9 * scale):
        return -1
    return 0


def _parts(triangles: np.ndarray, count: int) -> np.ndarray:
    """Each vertex's connected part, as the smallest vertex id in it: roots hooked to the
    smallest neighbouring root, then paths halved to the roots, until no edge joins two."""
    parent = np.arange(count, dtype=np.int64)
    u = np.concatenate([triangles[:, 0], triangles[:, 1]]).astype(np.int64)
    v = np.concatenate([triangles[:, 1], triangles[:, 2]]).astype(np.int64)
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


def _triple_products(positions: np.ndarray, triangles: np.ndarray,
                     chunk: int = 1 << 16) -> np.ndarray:
    """a·(b×c) per triangle (six times its signed volume from the origin), in chunks."""
    out = np.empty(len(triangles))
    for start in range(0, len(triangles), chunk):
        a, b, c = (positions[triangles[start:start + chunk, k]] for k in range(3))
        out[start:start + chunk] = np.einsum("ij,ij->i", a, np.cross(b, c))
    return out
