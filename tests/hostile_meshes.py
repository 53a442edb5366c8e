"""Hostile mesh files (issue 24), built in the test: each small, each claiming or causing
far more work than its size, each to be refused before a parser allocates for it."""

from __future__ import annotations

import base64
import json
import struct
import zlib

TRIANGLE = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def glb(header: dict, binary: bytes = b"") -> bytes:
    """A GLB of a JSON header and an optional BIN chunk, both padded to 4 bytes."""
    text = json.dumps(header).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text
    if binary:
        binary += b"\0" * (-len(binary) % 4)
        chunks += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def triangle_gltf(nodes: list[dict], roots: list[int]) -> dict:
    """A glTF header drawing one triangle (an embedded buffer) from the given nodes."""
    uri = "data:application/octet-stream;base64," + base64.b64encode(TRIANGLE).decode()
    return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": roots}],
            "nodes": nodes, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "buffers": [{"byteLength": 36, "uri": uri}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}]}


def glb_claiming_vertices(count: int = 30_000_000) -> bytes:
    """~316 bytes: a POSITION accessor of ``count`` vertices and no buffer at all."""
    return glb({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                "buffers": [], "bufferViews": [],
                "accessors": [{"componentType": 5126, "count": count, "type": "VEC3"}]})


def png_1bit(side: int) -> bytes:
    """A black ``side``² 1-bit PNG, written by hand (it compresses a thousandfold)."""
    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    row = b"\0" * (1 + (side + 7) // 8)
    pixels = zlib.compress(row * side, 9)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", side, side, 1, 0, 0, 0, 0))
            + chunk(b"IDAT", pixels) + chunk(b"IHDR"[:0] + b"IEND", b""))


def glb_with_textures(side: int = 8000, count: int = 2) -> bytes:
    """A textured triangle whose ``count`` PNG textures are ``side``² pixels each (~16 KB)."""
    images = [png_1bit(side) for _ in range(count)]
    uvs = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    blobs = [TRIANGLE, uvs, *images]
    views, offset = [], 0
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        offset += len(blob) + (-len(blob) % 4)
    binary = b"".join(blob + b"\0" * (-len(blob) % 4) for blob in blobs)
    textures = {"baseColorTexture": {"index": 0}}
    material = {"pbrMetallicRoughness": textures}
    if count > 1:
        material["normalTexture"] = {"index": 1}
    header = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
              "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                          "material": 0}]}],
              "materials": [material],
              "textures": [{"source": i} for i in range(count)],
              "images": [{"bufferView": 2 + i, "mimeType": "image/png"} for i in range(count)],
              "buffers": [{"byteLength": len(binary)}], "bufferViews": views,
              "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                             "min": [0, 0, 0], "max": [1, 1, 0]},
                            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]}
    return glb(header, binary)


def gltf_instanced(nodes: int = 200_000) -> bytes:
    """~3.5 MB of JSON: one triangle drawn by ``nodes`` nodes."""
    header = triangle_gltf([{"mesh": 0}] * nodes, list(range(nodes)))
    return json.dumps(header, separators=(",", ":")).encode()


def gltf_nested(depth: int = 5000) -> bytes:
    """A chain of ``depth`` nodes, each the only child of the one before, the last drawing."""
    nodes: list[dict] = [{"children": [i + 1]} for i in range(depth - 1)] + [{"mesh": 0}]
    return json.dumps(triangle_gltf(nodes, [0])).encode()


def ply_with_lines(lines: int) -> bytes:
    """An ASCII PLY of one triangle followed by ``lines`` short lines its header never declared."""
    return (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" + b"0\n" * lines)


def stl_solids(solids: int = 200_000) -> bytes:
    """An ASCII STL of ``solids`` one-triangle solids (~58 bytes each)."""
    one = (b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
           b"vertex 0 1 0\nendloop\nendfacet\nendsolid s\n")
    return one * solids


# Each file, and the words its refusal must contain.
HOSTILE = {
    "glb-3e7-vertices-no-buffer": (glb_claiming_vertices, "limit of 6000000"),
    "gltf-200000-instances": (gltf_instanced, "limit of 1000"),
    "ascii-ply-1.5M-undeclared-lines": (lambda: ply_with_lines(1_500_000),
                                        "limit of two a row"),
    "ascii-ply-30M-undeclared-lines": (lambda: ply_with_lines(30_000_000),
                                       "limit of two a row"),
    "gltf-5000-nodes-nested": (gltf_nested, "limit of 1000"),
    "ascii-stl-200000-solids": (stl_solids, "limit of"),
    "ascii-stl-300-solids": (lambda: stl_solids(300), "limit of 256 solids"),
    "gltf-json-nested-100000-deep": (
        lambda: b'{"asset":{"version":"2.0"},"extras":' + b"[" * 100_000 + b"]" * 100_000
        + b"}", "nested too deeply"),
}
