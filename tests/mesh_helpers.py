"""Mesh files of every format, generated in the test (never downloaded), and broken ones."""

from __future__ import annotations

import io
import struct

import numpy as np
import trimesh
import trimesh.visual

FORMATS = ("glb", "gltf", "obj", "ply", "stl")


def torus_with_uvs() -> trimesh.Trimesh:
    """An off-centre, scaled torus (so framing has work to do) with UVs on its vertices."""
    mesh = trimesh.creation.torus(1.0, 0.35, major_sections=48, minor_sections=24)
    angle = np.arctan2(mesh.vertices[:, 1], mesh.vertices[:, 0])
    uv = np.stack([(angle / (2 * np.pi)) % 1.0, (mesh.vertices[:, 2] + 0.35) / 0.7], 1)
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv)
    mesh.apply_transform(trimesh.transformations.rotation_matrix(0.6, (1, 0, 0)))
    mesh.apply_scale(40.0)
    mesh.apply_translation((300.0, -120.0, 55.0))
    return mesh


def mesh_bytes(fmt: str, mesh: trimesh.Trimesh | None = None) -> bytes:
    mesh = mesh if mesh is not None else torus_with_uvs()
    if fmt == "gltf":  # one JSON file with its buffer embedded as a data URI
        data = mesh.export(file_type="gltf", embed_buffers=True)
        return data["model.gltf"]
    data = mesh.export(file_type=fmt)
    return data.encode() if isinstance(data, str) else data


def binary_stl(vertices: np.ndarray) -> bytes:
    """A binary STL of triangles given as (M, 3, 3) corners (written by hand, NaN allowed)."""
    rows = [struct.pack("<12fH", 0, 0, 0, *tri.ravel(), 0) for tri in vertices]
    return b"\0" * 80 + struct.pack("<I", len(rows)) + b"".join(rows)


def broken_files() -> dict[str, bytes]:
    """Each refused with a 4xx and a message: name → bytes."""
    good_glb = mesh_bytes("glb")
    good_ply = mesh_bytes("ply")
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], dtype=float)
    nan = tri.copy()
    nan[0, 1, 0] = np.nan
    return {
        "not-a-mesh": b"\x89PNG\r\n\x1a\n" + bytes(200),
        "malformed-glb": b"glTF" + bytes(40),
        "truncated-glb": good_glb[: len(good_glb) // 2],
        "truncated-ply": good_ply[: len(good_ply) // 3],
        "malformed-obj": b"v 0 0 0\nv 1 0 0\nf 1 2 7\n",
        "zero-triangles-obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        "zero-triangles-stl": binary_stl(np.zeros((0, 3, 3))),
        "nan-vertex-stl": binary_stl(nan),
        "nan-vertex-obj": b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
        "zero-area-obj": b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    }


def load(data: bytes, fmt: str) -> trimesh.Trimesh:
    return trimesh.load(io.BytesIO(data), file_type=fmt, force="mesh")


def coverage_box(alpha: np.ndarray) -> tuple[int, int, int, int]:
    rows, cols = np.nonzero(alpha > 0.5)
    return rows.min(), rows.max(), cols.min(), cols.max()


def assert_framed(alpha: np.ndarray) -> None:
    """The object's bounding box is inside the image and covers a fair part of it."""
    h, w = alpha.shape
    top, bottom, left, right = coverage_box(alpha)
    assert top > 0 and left > 0 and bottom < h - 1 and right < w - 1, (top, bottom, left, right)
    assert (bottom - top + 1) * (right - left + 1) > 0.15 * h * w
    assert max(bottom - top + 1, right - left + 1) > 0.6 * min(h, w)


def glb_with_film(document, images: dict[str, bytes], film: dict) -> bytes:
    """``document`` (a pygltflib GLTF2 with a binary blob) with ``images`` (PNG bytes, by
    the KHR texture key each becomes) appended and its first material's film set to
    ``film`` and those textures, as another tool writes it: no Opaline extras."""
    import pygltflib

    blob = document.binary_blob()
    film = dict(film)
    for key, raw in images.items():
        blob += b"\0" * (-len(blob) % 4)
        document.bufferViews.append(pygltflib.BufferView(buffer=0, byteOffset=len(blob),
                                                         byteLength=len(raw)))
        blob += raw
        document.images.append(pygltflib.Image(bufferView=len(document.bufferViews) - 1,
                                               mimeType="image/png"))
        document.textures.append(pygltflib.Texture(source=len(document.images) - 1))
        film[key] = {"index": len(document.textures) - 1}
    material = document.materials[0]
    material.extras = {}
    material.extensions = {"KHR_materials_iridescence": film}
    document.extensionsUsed = ["KHR_materials_iridescence"]
    document.buffers[0].byteLength = len(blob)
    document.set_binary_blob(blob)
    return b"".join(document.save_to_bytes())
