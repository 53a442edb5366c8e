"""Back-face culling, where it cannot change the image.

Surfaces are drawn two-sided: an open mesh (a disc, a sheet of water, many uploaded
models) shows its back. But a closed surface seen from outside hides every back face
behind a front face, and llvmpipe shades whatever passes the depth test when it is
drawn: back faces drawn before the front faces covering them were shaded for nothing
(a sphere's draw cost 1.6x its culled one, for the same pixels). Culling is enabled
only when that holds for this view: the mesh is closed and consistently wound
(opaline.scene.closed), and its bounding box lies wholly in front of the near plane:
then no cut opens a window onto the inside, and the eye is outside the box, so outside
the mesh. (An eye inside the box but outside a concave mesh just draws both sides.)
"""

from __future__ import annotations

import numpy as np

from opaline.scene.closed import orientation, referenced


class Culling:
    """What one scene's mesh allows: decided once per mesh, then per view from 8 corners."""

    def __init__(self, positions: np.ndarray, indices: np.ndarray,
                 planes: bool = True) -> None:
        # Each triangle's plane (its normal, n·p), for shows_back: kept for the built-in
        # meshes, whose few thousand triangles cost little; not for a user's (up to 2M).
        self._planes: tuple[np.ndarray, np.ndarray] | None = None
        if planes:
            corners = positions.astype(np.float64)[indices.reshape(-1, 3)]
            normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            self._planes = (normals, np.einsum("ij,ij->i", normals, corners[:, 0]))
        self.sign = orientation(positions, indices)
        closed = self.sign != 0
        self.corners = np.zeros((8, 3))
        if closed:
            points, _ = referenced(positions, indices)  # not a file's unused vertices
            low, high = points.min(axis=0), points.max(axis=0)
            self.corners = np.array([[(low, high)[(i >> k) & 1][k] for k in range(3)]
                                     for i in range(8)])

    def front_face(self, model: np.ndarray, view_proj: np.ndarray) -> str | None:
        """GL's front-face winding to cull the back faces by, or None to draw both sides."""
        if self.sign == 0:
            return None
        model = np.asarray(model, dtype=np.float64)
        # The matrices as the renderer uploads them: for row vectors, translation in the
        # last row (GL reads the bytes column-major, which transposes them).
        determinant = float(np.linalg.det(model[:3, :3]))
        if determinant == 0.0 or not np.isfinite(determinant):
            return None
        # In front of the near plane is a half-space in homogeneous coordinates, so the
        # mesh's bounding box (convex) being in front means every vertex is: nothing is
        # cut open, and the eye is outside the box, so outside the mesh.
        clip = np.c_[self.corners, np.ones(8)] @ model @ np.asarray(view_proj, dtype=np.float64)
        if not np.all((clip[:, 3] > 0.0) & (clip[:, 2] > -clip[:, 3])):
            return None
        # A mirroring model matrix turns counter-clockwise triangles clockwise on screen.
        return "ccw" if self.sign * determinant > 0.0 else "cw"

    def shows_back(self, model: np.ndarray, eye: tuple[float, ...]) -> bool:
        """Whether the eye may see some triangle from behind (the side its winding, and so
        its vertex normals, do not face): without the planes, it may. The sign of
        n·(eye − p) is kept by any affine model matrix (normals turn by its inverse
        transpose), so the test runs in object space."""
        if self._planes is None:
            return True
        normals, offsets = self._planes
        eye_object = (np.append(np.asarray(eye, dtype=np.float64), 1.0)
                      @ np.linalg.inv(np.asarray(model, dtype=np.float64)))[:3]
        return bool(np.any(normals @ eye_object < offsets))
