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


def _welded_triangles(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Triangles over welded vertex ids, without those that collapse to a line or point."""
    positions = np.asarray(positions, dtype=np.float64)
    extent = float(np.ptp(positions, axis=0).max()) if len(positions) else 0.0
    if not np.isfinite(extent) or extent <= 0.0:
        return np.empty((0, 3), dtype=np.int64)
    grid = np.round((positions - positions.min(axis=0)) * (WELD_STEPS / extent)).astype(np.int64)
    # One integer per grid point (21 bits an axis): a 1-D unique is far faster than rows'.
    keys = (grid[:, 0] << 42) | (grid[:, 1] << 21) | grid[:, 2]
    _, weld = np.unique(keys, return_inverse=True)
    triangles = weld.reshape(-1)[np.asarray(indices, dtype=np.int64).reshape(-1, 3)]
    a, b, c = triangles.T
    return triangles[(a != b) & (b != c) & (c != a)]


def orientation(positions: np.ndarray, indices: np.ndarray) -> int:
    """+1: closed, consistently wound, counter-clockwise seen from outside; -1: the same
    wound clockwise; 0: open, non-manifold, inconsistently wound, or without volume.

    Closed and consistent means every directed edge occurs exactly once and so does its
    reverse: each edge is shared by two triangles that traverse it in opposite senses.
    """
    triangles = _welded_triangles(positions, indices)
    if len(triangles) < 4:
        return 0
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    count = int(triangles.max()) + 1
    forward = np.sort(edges[:, 0] * count + edges[:, 1])
    if np.any(forward[1:] == forward[:-1]):
        return 0
    if not np.array_equal(forward, np.sort(edges[:, 1] * count + edges[:, 0])):
        return 0
    corners = np.asarray(positions, dtype=np.float64)[np.asarray(indices).reshape(-1, 3)]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    scale = float(np.ptp(corners.reshape(-1, 3), axis=0).max()) ** 3
    if not abs(volume) > 1e-9 * scale:
        return 0
    return 1 if volume > 0 else -1
