"""Vertex normals of user meshes: smooth across split vertices, sharp across creases."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from opaline.scene.meshfile import parse_mesh
from opaline.scene.normals import CREASE_DEGREES, vertex_normals

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def split_along_seam(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh with the faces on the x < 0 side given copies of their vertices: one
    surface, two patches that share positions but no vertex (as the teapot's patches).
    Also each vertex's original index."""
    positions = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64).copy()
    west = positions[faces].mean(axis=1)[:, 0] < 0.0
    used = np.unique(faces[west])
    copy_of = np.full(len(positions), -1)
    copy_of[used] = len(positions) + np.arange(len(used))
    faces[west] = copy_of[faces[west]]
    original = np.concatenate([np.arange(len(positions)), used])
    return np.concatenate([positions, positions[used]]), faces, original


def test_a_seam_on_a_smooth_surface_is_closed():
    sphere = trimesh.creation.icosphere(subdivisions=3)
    positions, faces, original = split_along_seam(sphere)
    whole = vertex_normals(np.asarray(sphere.vertices), np.asarray(sphere.faces))
    split = vertex_normals(positions, faces)
    corners = faces.reshape(-1)
    # Every corner, on either patch, has the unsplit sphere's normal there: at the seam
    # the average over both patches, not over its own side only.
    np.testing.assert_allclose(split[corners], whole[original[corners]], atol=1e-12)


def test_a_cube_with_vertices_per_face_keeps_its_edges():
    box = trimesh.creation.box()
    positions = np.asarray(box.vertices)[np.asarray(box.faces)].reshape(-1, 3)
    faces = np.arange(len(positions)).reshape(-1, 3)
    normals = vertex_normals(positions, faces)
    face_normals = np.repeat(np.asarray(box.face_normals), 3, axis=0)
    # The two triangles of one face agree and average; faces 90° apart stay apart.
    np.testing.assert_allclose(normals, face_normals, atol=1e-12)
    assert CREASE_DEGREES < 90.0


def test_the_teapot_shades_across_its_patch_borders():
    mesh, _ = parse_mesh((ASSETS / "teapot.obj").read_bytes(), "obj")
    positions = mesh.positions.astype(np.float64)
    normals = mesh.normals.astype(np.float64)
    _, group = np.unique(positions, axis=0, return_inverse=True)
    group = group.reshape(-1)
    first = np.zeros(group.max() + 1, dtype=np.int64)
    first[group[::-1]] = np.arange(len(group))[::-1]
    angle = np.degrees(np.arccos(np.clip(np.sum(normals * normals[first[group]], axis=1),
                                         -1.0, 1.0)))
    smooth = angle < CREASE_DEGREES
    assert np.count_nonzero(np.bincount(group) > 1) > 100  # the file splits its patches
    assert angle[smooth].max() < 0.1  # float32's rounding; before, copies up to 40° apart
