"""Tangent frames for meshes from files: from UVs where they exist, else a chosen field.

The anisotropic MDFs orient their highlight along the tangent, so a mesh
without one cannot show them. With UVs the tangent is dP/du, computed the way
MikkTSpace does at heart (per-triangle UV derivative, accumulated per vertex
with corner-angle weights, then Gram-Schmidt against the vertex normal); it is
not bit-identical to MikkTSpace (no vertex splitting on handedness flips: the
renderer's frame is ``(t, cross(n, t), n)`` and needs no sign). Without UVs the
request picks a field: concentric about an axis (the CD's tracks), or an axis
direction projected onto each tangent plane (brushed metal). Every vertex gets
a unit tangent perpendicular to its normal; where a field degenerates (the
pole of a concentric field, a normal parallel to the projected direction) a
fallback keeps it defined.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FIELDS = ("auto", "uv", "concentric", "projected")
EPS = 1e-12


def _unit_rows(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows normalised, and which rows were long enough to normalise."""
    length = np.linalg.norm(v, axis=1)
    ok = length > 1e-8
    out = np.zeros_like(v)
    out[ok] = v[ok] / length[ok, None]
    return out, ok


def project(normals: np.ndarray, direction: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``direction`` minus its normal component, unit; and where that was possible."""
    d = np.broadcast_to(np.asarray(direction, dtype=np.float64), normals.shape)
    return _unit_rows(d - normals * np.sum(normals * d, axis=1, keepdims=True))


def any_perpendicular(normals: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to each normal (the least aligned axis projected)."""
    axis = np.eye(3)[np.argmin(np.abs(normals), axis=1)]
    return project(normals, axis)[0]


def projected(normals: np.ndarray, direction: npt.ArrayLike) -> np.ndarray:
    t, ok = project(normals, direction)
    t[~ok] = any_perpendicular(normals[~ok])
    return t


def concentric(positions: np.ndarray, normals: np.ndarray, axis: npt.ArrayLike,
               centre: npt.ArrayLike) -> np.ndarray:
    """Circles about the line through ``centre`` along ``axis``, projected onto each surface."""
    axis = np.asarray(axis, dtype=np.float64)
    around = np.cross(axis, positions - np.asarray(centre, dtype=np.float64))
    t, ok = project(normals, around)
    t[~ok] = projected(normals[~ok], axis)
    return t


def from_uvs(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
             faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dP/du per vertex, orthogonalised; and which vertices got a usable one."""
    p = positions[faces]  # (M, 3 corners, 3)
    w = uvs[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    du1, dv1 = w[:, 1, 0] - w[:, 0, 0], w[:, 1, 1] - w[:, 0, 1]
    du2, dv2 = w[:, 2, 0] - w[:, 0, 0], w[:, 2, 1] - w[:, 0, 1]
    det = du1 * dv2 - du2 * dv1
    usable = np.abs(det) > EPS
    scale = np.where(usable, 1.0 / np.where(usable, det, 1.0), 0.0)
    # Mirrored UVs flip the sign of det; the direction of increasing u is what we want.
    face_t = (e1 * dv2[:, None] - e2 * dv1[:, None]) * scale[:, None]
    face_t, _ = _unit_rows(face_t)
    accum = np.zeros_like(positions)
    for corner in range(3):
        a = p[:, (corner + 1) % 3] - p[:, corner]
        b = p[:, (corner + 2) % 3] - p[:, corner]
        cos = np.sum(a * b, axis=1) / np.maximum(
            np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), EPS)
        angle = np.arccos(np.clip(cos, -1.0, 1.0))
        np.add.at(accum, faces[:, corner], face_t * angle[:, None])
    return project(normals, accum) if len(accum) else (accum, np.zeros(0, bool))


def tangent_frame(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray | None,
                  faces: np.ndarray, field: str = "auto",
                  axis: npt.ArrayLike = (0.0, 1.0, 0.0)
                  ) -> tuple[np.ndarray, str]:
    """Unit tangents (float64) for every vertex, and the field actually used.

    ``auto``: from the UVs if the mesh has them, else concentric about ``axis``
    through the bounds' centre. ``uv`` without UVs is an error, not a silent
    substitute: the caller asked for the mesh's own parameterisation."""
    if field not in FIELDS:
        raise ValueError(f"tangent field {field!r} is not known: choose one of {', '.join(FIELDS)}")
    axis = np.asarray(axis, dtype=np.float64)
    if not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-9:
        raise ValueError(f"tangent_axis={tuple(map(float, axis))} must be a finite, non-zero vector")
    axis = axis / np.linalg.norm(axis)
    centre = (positions.min(axis=0) + positions.max(axis=0)) * 0.5
    if field in ("auto", "uv") and uvs is not None:
        t, ok = from_uvs(positions, normals, uvs, faces)
        t[~ok] = concentric(positions[~ok], normals[~ok], axis, centre)
        return t, "uv"
    if field == "uv":
        raise ValueError("tangent_field='uv' but the mesh has no UV coordinates: "
                         "choose 'concentric' or 'projected'")
    if field == "projected":
        return projected(normals, axis), "projected"
    return concentric(positions, normals, axis, centre), "concentric"
