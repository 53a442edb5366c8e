"""A .glb's thin-film textures (KHR_materials_iridescence on its first material): the
thickness texture (its G channel, KHR's) and the factor texture (R), each a [0, 1]
float32 field stored as Opaline stores its own, row 0 at glTF's t = 0, which is v = 1
(glTF's t runs down the image, Opaline's v up: the rows map unchanged).

A user's .glb that carries a thickness texture draws its film with it (a ``glb``
thickness field, ``scene.thickness``), in the mesh's own UVs, in place of its preset's;
one that carries a factor texture weighs its film by it (a ``glb-factor`` field, the
preset's ``weight_map``); the export writes both textures back (``output.gltf``). Every image is checked before
it is decoded: at most ``MAX_TEXELS`` texels, PNG or JPEG, in the file's binary chunk.
"""

from __future__ import annotations

import io
import json
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
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

    @classmethod
    def from_keys(cls, fields: dict[str, np.ndarray]) -> FilmTextures:
        return cls(fields.get("iridescenceThicknessTexture"), fields.get("iridescenceTexture"))

    def by_key(self) -> dict[str, np.ndarray]:
        """The fields present, by the KHR texture each is (the inverse of ``from_keys``)."""
        fields = {"iridescenceThicknessTexture": self.thickness,
                  "iridescenceTexture": self.factor}
        return {key: field for key, field in fields.items() if field is not None}


def load_document(data: bytes) -> gl.GLTF2:
    """A .glb's document; ValueError saying why where the bytes are not one."""
    # Imported here: the presets' module imports this one, and pygltflib was ~40 ms of a
    # cold `opaline render` that reads no .glb (tests/test_cold_start.py).
    import pygltflib as gl

    if data[:4] == b"glTF" and len(data) >= 12:  # the header's length: pygltflib reads
        declared = int.from_bytes(data[8:12], "little")  # a cut file as an empty document
        if len(data) < declared:
            raise ValueError(f"the .glb is cut short: {len(data)} of its {declared} bytes")
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
    extensions = document.materials[0].extensions
    film = extensions.get(IRIDESCENCE) if isinstance(extensions, dict) else None
    return film if isinstance(film, dict) else {}


def _index(value: Any, items: Any, what: str, key: str) -> int:
    count = len(items) if isinstance(items, list) else 0
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < count:
        raise ValueError(f"{IRIDESCENCE}.{key}: no {what} {value!r} in the file")
    return value


def _image_bytes(document: gl.GLTF2, info: Any, key: str) -> bytes:
    index = _index(info.get("index") if isinstance(info, dict) else None,
                   document.textures, "texture", key)
    source = _index(document.textures[index].source, document.images, "image", key)
    view_index = document.images[source].bufferView
    if view_index is None:
        raise ValueError(f"{IRIDESCENCE}.{key}: only images in the .glb's binary chunk are read")
    view = document.bufferViews[_index(view_index, document.bufferViews, "bufferView", key)]
    blob = document.binary_blob() or b""
    start, length = view.byteOffset or 0, view.byteLength
    if not (isinstance(start, int) and isinstance(length, int) and start >= 0 and length >= 0
            and start + length <= len(blob)):
        raise ValueError(f"{IRIDESCENCE}.{key}: its image is not inside the binary chunk")
    return bytes(blob[start:start + length])


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
            if image.mode.startswith("I"):  # 16-bit grey: every channel is the grey
                field: np.ndarray = np.asarray(image, dtype=np.float32) / 65535.0
                return field
            values = np.asarray(image.convert("RGB").split()[channel], dtype=np.float32)
    except (OSError, Image.DecompressionBombError) as error:
        raise ValueError(f"{IRIDESCENCE}.{key}: not a readable image: {error}") from None
    return values / 255.0


def read_film_textures(data: bytes, keys: tuple[str, ...] = tuple(CHANNELS)) -> FilmTextures:
    """The thickness and factor textures of the first material's film (of ``keys``, the
    KHR names), each None where the file has none; ValueError naming the texture where
    one cannot be read."""
    document = load_document(data)
    film = _film(document)
    fields = {key: _channel(_image_bytes(document, film[key], key), CHANNELS[key], key)
              for key in keys if key in film}
    return FilmTextures.from_keys(fields)


def texture_names(head: bytes) -> set[str]:
    """The KHR textures a .glb's first material's film names, from the start of the file
    (its JSON chunk; the rest is not needed): none where it is not a .glb or has no film."""
    if len(head) < 20 or head[:4] != b"glTF" or head[16:20] != b"JSON":
        return set()
    length = struct.unpack("<I", head[12:16])[0]
    try:
        document = json.loads(head[20:20 + length])
        film = document["materials"][0]["extensions"][IRIDESCENCE]
    except (ValueError, LookupError, TypeError, RecursionError):
        return set()  # the mesh loader says what is wrong with the file
    return set(CHANNELS) & set(film) if isinstance(film, dict) else set()


def film_texture_names(path: Path) -> set[str]:
    """The KHR textures a mesh file's film names (none where it is no .glb): its JSON chunk
    alone is read (a request's scene is prepared from it; the mesh loader decodes and
    checks the images, ``check_film_textures``)."""
    with open(path, "rb") as stream:
        head = stream.read(20)
        if len(head) == 20 and head[:4] == b"glTF":
            head += stream.read(struct.unpack("<I", head[12:16])[0])
    return texture_names(head)


def check_film_textures(data: bytes) -> None:
    """ValueError naming the film texture of a .glb that cannot be drawn or exported."""
    if texture_names(data):
        read_film_textures(data)
