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
    triangles = weld.reshape(-1).astype(np.int32)[np.asarray(indices).reshape(-1, 3)]
    a, b, c = triangles.T
    return triangles[(a != b) & (b != c) & (c != a)]


def orientation(positions: np.ndarray, indices: np.ndarray) -> int:
    """+1: closed, consistently wound, counter-clockwise seen from outside; -1: the same
    wound clockwise; 0: open, non-manifold, inconsistently wound, without volume, or over
    ``MAX_TRIANGLES``.

    Closed and consistent means every directed edge occurs exactly once and so does its
    reverse: each edge is shared by two triangles that traverse it in opposite senses.
    """
    if len(indices) > MAX_TRIANGLES:
        return 0
    triangles = _welded_triangles(positions, indices)
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
    volume = _signed_volume(np.asarray(positions, dtype=np.float64), np.asarray(indices))
    scale = float(np.ptp(np.asarray(positions, dtype=np.float64), axis=0).max()) ** 3
    if not abs(volume) > 1e-9 * scale:
        return 0
    return 1 if volume > 0 else -1


def _signed_volume(positions: np.ndarray, indices: np.ndarray, chunk: int = 1 << 16) -> float:
    """Six times the enclosed volume (the sum of a·(b×c)), a chunk of triangles at a time."""
    triangles = indices.reshape(-1, 3)
    total = 0.0
    for start in range(0, len(triangles), chunk):
        a, b, c = (positions[triangles[start:start + chunk, k]] for k in range(3))
        total += float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum())
    return total
