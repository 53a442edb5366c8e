"""The mesh every generator returns, and the helpers that build one.

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

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt


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


def make_mesh(positions: npt.ArrayLike, normals: npt.ArrayLike, tangents: npt.ArrayLike,
              uvs: npt.ArrayLike, indices: npt.ArrayLike) -> Mesh:
    """Normalise in float64 before rounding, so float32 vectors are unit to ~1e-7."""
    normals = unit(normals)
    tangents = unit(tangents)
    return Mesh(
        positions=np.asarray(positions, dtype=np.float32),
        normals=normals.astype(np.float32),
        tangents=tangents.astype(np.float32),
        uvs=np.asarray(uvs, dtype=np.float32),
        indices=np.asarray(indices, dtype=np.uint32),
    )


def unit(v: npt.ArrayLike) -> np.ndarray:
    vectors = np.asarray(v, dtype=np.float64)
    out: np.ndarray = vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
    return out


def grid_indices(rows: int, cols: int) -> np.ndarray:
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
