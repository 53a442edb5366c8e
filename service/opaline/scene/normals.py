"""Vertex normals of a user's mesh, smooth across seams where a file splits its vertices.

Files often repeat a vertex where patches, UV islands or material groups meet (the Utah
teapot's OBJ shares no vertex between its patches). Each copy's normal then averages only
its own side's triangles, and the shading, the tangent field and the projected thickness
field break along the seam. Copies at one position are therefore averaged together, as a
modelling tool's "smooth by angle" does, where their own normals are within
``CREASE_DEGREES`` of each other: a seam on a smooth surface closes, while a cube whose
faces have vertices of their own keeps its edges.
"""

from __future__ import annotations

import numpy as np

CREASE_DEGREES = 60.0
MAX_COPIES = 32  # copies of one position averaged; a larger pile (a degenerate file) is left
PAIRS_PER_CHUNK = 1 << 22  # bounds the pairwise comparison's memory (~100 MB)


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit normals: area-weighted face normals summed per vertex, then over the copies of
    each position that agree within the crease angle."""
    summed = _area_weighted(positions, faces)
    summed = _across_copies(positions, summed)
    length = np.linalg.norm(summed, axis=1)
    bad = length < 1e-30  # unused vertices and cancelling fans: any unit vector will do
    summed[bad] = (0.0, 1.0, 0.0)
    length[bad] = 1.0
    unit: np.ndarray = summed / length[:, None]
    return unit


def _area_weighted(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Face normals (the cross product's length is 2×area) summed per vertex."""
    face_n = np.cross(positions[faces[:, 1]] - positions[faces[:, 0]],
                      positions[faces[:, 2]] - positions[faces[:, 0]])
    summed = np.zeros_like(positions)
    for corner in range(3):
        np.add.at(summed, faces[:, corner], face_n)
    return summed


def _across_copies(positions: np.ndarray, summed: np.ndarray) -> np.ndarray:
    """Each vertex's sum plus those of the other vertices at its position whose normal is
    within the crease angle of its own."""
    _, group, counts = np.unique(positions, axis=0, return_inverse=True, return_counts=True)
    group = group.reshape(-1)
    copies = counts[group]
    order = np.argsort(group, kind="stable")
    order = order[(copies[order] >= 2) & (copies[order] <= MAX_COPIES)]
    if len(order) == 0:
        return summed
    unit = summed / np.maximum(np.linalg.norm(summed, axis=1), 1e-30)[:, None]
    merged = summed.copy()
    threshold = np.cos(np.radians(CREASE_DEGREES))
    sizes = copies[order]
    for k in np.unique(sizes):
        members = order[sizes == k].reshape(-1, k)  # sorted by group: k copies a row
        step = max(1, PAIRS_PER_CHUNK // (k * k))
        for start in range(0, len(members), step):
            rows = members[start:start + step]
            agree = np.einsum("gid,gjd->gij", unit[rows], unit[rows]) > threshold
            merged[rows] = np.einsum("gij,gjd->gid", agree, summed[rows])
    return merged
