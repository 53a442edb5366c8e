"""Object-space (triplanar) projection of a preset's maps onto a user's mesh: the float64
twin of ``glsl/lib/triplanar.glsl``, and the mesh's projection frame.

The presets' thickness fields and normal maps are made for their own geometry's UVs; a
scanned mesh usually has none (every vertex at uv 0, one constant film). Instead each
map is projected along the three object axes and the three samples are blended by the
normal: weights ``|n|^4``, normalised (a fixed sharpness: wide enough to hide the seams,
narrow enough that the tablets of nacre do not ghost). The planes follow Golus ("Normal
Mapping for a Triplanar Shader", 2017): x → (z, y), y → (x, z), z → (x, y), so that the
two side projections keep v along the mesh's up axis and a draining film drains down.

Normal maps use the whiteout blend (Barré-Brisebois and Hill, "Blending in Detail",
2012, in Golus's triplanar form): each plane's tangent-space normal gets the geometric
normal's in-plane components added and its z scaled by the normal's axis component. No
sign flip is needed on the negative faces: a height field's slope is the same in the
projected axes seen from either side, and ``|z|`` carries the face's direction.

Scale: one map tile spans the mesh's longest bounding-box side, as one spans each face of
the nacre box or the whole oil sheet, so a bunny shows as many tablets across as the box.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

SHARPNESS = 4  # the blend's exponent; glsl/lib/triplanar.glsl squares twice
MeshProjection = Literal["auto", "object"]


def frame(positions: np.ndarray) -> tuple[tuple[float, float, float], float]:
    """Origin (the bounds' minimum corner) and scale (one tile per longest side) that map
    object positions to projection coordinates ``q = (p - origin) * scale``."""
    points = np.asarray(positions, dtype=np.float64)
    low, high = points.min(axis=0), points.max(axis=0)
    extent = float((high - low).max())
    return (float(low[0]), float(low[1]), float(low[2])), 1.0 / extent if extent > 0 else 1.0


def projects(mesh_projection: MeshProjection, uvs: np.ndarray) -> bool:
    """Whether a user's mesh takes the maps in object space: the preset asks for it, or the
    mesh has no UVs (meshfile gives such a mesh all-zero UVs: no parameterisation at all)."""
    if mesh_projection == "object" or len(uvs) == 0:
        return True
    return not bool(np.ptp(uvs, axis=0).max() > 0)


def weights(n: np.ndarray) -> np.ndarray:
    """Blend weights (…, 3) from object-space normals; equal thirds for a zero normal."""
    w = np.asarray(n, dtype=np.float64) ** 2
    w = w * w
    total = w.sum(axis=-1, keepdims=True)
    safe = np.where(total > 1e-30, total, 1.0)
    return np.where(total > 1e-30, w / safe, 1.0 / 3.0)


def coords(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each plane's texture coordinates: along x (z, y), along y (x, z), along z (x, y)."""
    q = np.asarray(q, dtype=np.float64)
    return q[..., [2, 1]], q[..., [0, 2]], q[..., [0, 1]]


def whiteout(tx: np.ndarray, ty: np.ndarray, tz: np.ndarray, n: np.ndarray,
             w: np.ndarray) -> np.ndarray:
    """The planes' tangent-space normals blended into one object-space unit normal."""
    n = np.asarray(n, dtype=np.float64)
    bx = np.concatenate([tx[..., :2] + n[..., [2, 1]], np.abs(tx[..., 2:]) * n[..., :1]], axis=-1)
    by = np.concatenate([ty[..., :2] + n[..., [0, 2]], np.abs(ty[..., 2:]) * n[..., 1:2]], axis=-1)
    bz = np.concatenate([tz[..., :2] + n[..., [0, 1]], np.abs(tz[..., 2:]) * n[..., 2:]], axis=-1)
    out = (bx[..., [2, 1, 0]] * w[..., :1] + by[..., [0, 2, 1]] * w[..., 1:2]
           + bz * w[..., 2:])
    length = np.linalg.norm(out, axis=-1, keepdims=True)
    return np.where(length > 1e-15, out / np.where(length > 0, length, 1.0), 0.0)


def bilinear(texels: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """GL's LINEAR, REPEAT lookup of a (rows = v, cols = u, C) map, row 0 at v = 0."""
    height, width = texels.shape[:2]
    x = np.asarray(uv[..., 0], dtype=np.float64) * width - 0.5
    y = np.asarray(uv[..., 1], dtype=np.float64) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    i0, j0 = x0.astype(int) % width, y0.astype(int) % height
    i1, j1 = (i0 + 1) % width, (j0 + 1) % height
    top = texels[j0, i0] * (1 - fx) + texels[j0, i1] * fx
    bottom = texels[j1, i0] * (1 - fx) + texels[j1, i1] * fx
    blended: np.ndarray = top * (1 - fy) + bottom * fy
    return blended


def sample(texels: np.ndarray, q: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What ``triplanar_normal`` and ``triplanar_scalar`` give for a map whose rgb is a
    tangent-space normal map and alpha a scalar field: (object-space normal, scalar)."""
    w = weights(n)
    planes = [bilinear(texels, uv) for uv in coords(q)]
    normal = whiteout(planes[0][..., :3], planes[1][..., :3], planes[2][..., :3], n, w)
    scalar = sum(w[..., i] * planes[i][..., 3] for i in range(3))
    return normal, scalar
