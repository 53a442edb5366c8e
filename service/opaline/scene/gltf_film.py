"""A .glb's thin-film textures (KHR_materials_iridescence on its first material): the
thickness texture (its G channel, KHR's) and the factor texture (R), each a [0, 1]
float32 field stored as Opaline stores its own, row 0 at glTF's t = 0, which is v = 1
(glTF's t runs down the image, Opaline's v up: the rows map unchanged).

A user's .glb that carries a thickness texture draws its film with it (a ``glb``
thickness field, ``scene.thickness``), in the mesh's own UVs, in place of its preset's;
the export writes both textures back (``output.gltf``). Every image is checked before
it is decoded: at most ``MAX_TEXELS`` texels, PNG or JPEG, in the file's binary chunk.
"""

from __future__ import annotations

import io
import json
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pygltflib as gl

IRIDESCENCE = "KHR_materials_iridescence"
# A texture's texels at most: a generated thickness field's largest (thickness.RESOLUTION).
MAX_TEXELS = 4096 * 4096
# Which channel KHR reads of each texture.
CHANNELS = {"iridescenceThicknessTexture": 1, "iridescenceTexture": 0}


@dataclass(frozen=True)
class FilmTextures:
    thickness: np.ndarray | None  # [0, 1] → [film_thickness_min, film_thickness_max]
    factor: np.ndarray | None  # [0, 1], times iridescenceFactor


def load_document(data: bytes) -> gl.GLTF2:
    """A .glb's document; ValueError saying why where the bytes are not one."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pygltflib warns, then may answer None
            document = gl.GLTF2.load_from_bytes(data)
    except Exception as exc:  # pygltflib fails in many ways on bad bytes
        raise ValueError(f"not a readable .glb: {type(exc).__name__}: {exc}") from None
    if document is None:
        raise ValueError("not a readable .glb")
    return document


def _film(document: gl.GLTF2) -> dict[str, Any]:
    if not document.materials:
        return {}
    film = (document.materials[0].extensions or {}).get(IRIDESCENCE)
    return film if isinstance(film, dict) else {}


def _image_bytes(document: gl.GLTF2, info: Any, key: str) -> bytes:
    index = info.get("index") if isinstance(info, dict) else None
    if not isinstance(index, int) or not 0 <= index < len(document.textures):
        raise ValueError(f"{IRIDESCENCE}.{key}: no texture {index!r} in the file")
    source = document.textures[index].source
    if not isinstance(source, int) or not 0 <= source < len(document.images):
        raise ValueError(f"{IRIDESCENCE}.{key}: its texture has no image")
    view_index = document.images[source].bufferView
    if not isinstance(view_index, int) or not 0 <= view_index < len(document.bufferViews):
        raise ValueError(f"{IRIDESCENCE}.{key}: only images in the .glb's binary chunk are read")
    view = document.bufferViews[view_index]
    blob = document.binary_blob() or b""
    start = view.byteOffset or 0
    if start + view.byteLength > len(blob):
        raise ValueError(f"{IRIDESCENCE}.{key}: its image runs past the binary chunk")
    return bytes(blob[start:start + view.byteLength])


def _channel(raw: bytes, channel: int, key: str) -> np.ndarray:
    from PIL import Image  # only a film texture needs Pillow here

    try:
        with Image.open(io.BytesIO(raw)) as image:
            width, height = image.size
            if width * height > MAX_TEXELS:
                raise ValueError(f"{IRIDESCENCE}.{key}: {width}×{height} texels, more than "
                                 f"{MAX_TEXELS}")
            if image.format not in ("PNG", "JPEG"):
                raise ValueError(f"{IRIDESCENCE}.{key}: a {image.format} image, not PNG or JPEG")
            bands = image.convert("RGB").split()
            values = np.asarray(bands[channel], dtype=np.float32)
    except OSError as error:
        raise ValueError(f"{IRIDESCENCE}.{key}: not a readable image: {error}") from None
    field: np.ndarray = values / 255.0
    return field


def read_film_textures(data: bytes) -> FilmTextures:
    """The thickness and factor textures of the first material's film, each None where
    the file has none; ValueError naming the texture where one cannot be read."""
    document = load_document(data)
    film = _film(document)
    fields = {key: _channel(_image_bytes(document, film[key], key), channel, key)
              for key, channel in CHANNELS.items() if key in film}
    return FilmTextures(fields.get("iridescenceThicknessTexture"),
                        fields.get("iridescenceTexture"))


def has_thickness_texture(path: Path) -> bool:
    """Whether a mesh file is a .glb whose first material's film names a thickness texture:
    its JSON chunk alone is read (a request's scene is prepared from it; the image is
    decoded when the scene is built, where a bad one is reported)."""
    with open(path, "rb") as stream:
        header = stream.read(20)
        if len(header) < 20 or header[:4] != b"glTF" or header[16:20] != b"JSON":
            return False
        length = struct.unpack("<I", header[12:16])[0]
        text = stream.read(length)
    try:
        document = json.loads(text)
        film = document["materials"][0]["extensions"][IRIDESCENCE]
    except (ValueError, LookupError, TypeError):
        return False  # the mesh loader says what is wrong with the file
    return isinstance(film, dict) and "iridescenceThicknessTexture" in film
