"""What a mesh file declares, checked against the limits before any parser allocates for it.

trimesh believes a file's counts: an accessor claiming 3e7 vertices with no
buffer behind it becomes gigabytes of zeros, every node instancing a mesh a
copy, every ASCII line a NumPy array. So the counts are read here first from
headers and by counting bytes (nothing proportional to a count is built),
and a file that claims more than the limits allow is a ``MeshError`` naming
the limit. glTF images are dropped before trimesh sees them: the renderer
never samples a file's textures, and decoding an 8000² PNG costs 64 MB.

Text formats cost far more per element than binary ones (trimesh keeps a
Python object or an array per line, 120-900 bytes), so they have their own
smaller limits; large meshes belong in GLB, binary PLY or binary STL.
"""

from __future__ import annotations

import json
import struct
from typing import Any

from opaline.scene.gltf_limits import LimitError, check_gltf_header

__all__ = ["LimitError", "check", "vertex_limit"]


# Text files: separators (whitespace and every line break str.splitlines knows) bound both
# trimesh's per-line arrays and a polygon's per-index work: about 120 bytes each at worst.
TEXT_MAX_FIELDS = 2_000_000
TEXT_SEPARATORS = (b" ", b"\t", b"\n", b"\r", b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e",
                   b"\xc2\x85", b"\xe2\x80\xa8", b"\xe2\x80\xa9")
PLY_MAX_ROWS = 1_000_000  # an ASCII PLY row is an array of its own (~170 bytes)
STL_MAX_SOLIDS = 256  # trimesh's time grows faster than the count (1000: 1.3 s)
TEXT_HINT = "; larger meshes can be sent as GLB, binary PLY or binary STL"


def vertex_limit(max_triangles: int) -> int:
    """Vertices (and index entries) a file may declare: three per allowed triangle."""
    return 3 * max_triangles


def check(data: bytes, fmt: str, max_triangles: int) -> bytes:
    """The bytes trimesh should parse (glTF images dropped), or ``LimitError``."""
    if fmt in ("glb", "gltf"):
        return _gltf(data, fmt, max_triangles)
    if fmt == "ply":
        _ply(data, max_triangles)
    elif fmt == "stl" and not _binary_stl(data):
        _ascii_stl(data, max_triangles)
    elif fmt == "obj":
        _text_fields(data, "OBJ")
    return data


def _binary_stl(data: bytes) -> bool:
    return len(data) >= 84 and 84 + 50 * int.from_bytes(data[80:84], "little") == len(data)


def _text_fields(data: bytes, what: str) -> None:
    fields = sum(data.count(sep) for sep in TEXT_SEPARATORS)
    if fields > TEXT_MAX_FIELDS:
        raise LimitError(f"{what} text with about {fields} fields (numbers, indices, line "
                         f"breaks) is over this service's limit of {TEXT_MAX_FIELDS}{TEXT_HINT}")


def _ascii_stl(data: bytes, max_triangles: int) -> None:
    _text_fields(data, "ASCII STL")
    lower = data.lower()  # trimesh reads the keywords in any case
    solids = lower.count(b"endsolid")
    if solids > STL_MAX_SOLIDS:
        raise LimitError(f"ASCII STL with {solids} solids is over this service's limit of "
                         f"{STL_MAX_SOLIDS} solids a file")
    facets = lower.count(b"endfacet")
    if facets > max_triangles:
        raise LimitError(f"{facets} triangles is over this service's limit of {max_triangles}")


def _ply(data: bytes, max_triangles: int) -> None:
    end = data.find(b"end_header")
    if end < 0:
        return  # no header to read: trimesh's own error says so
    lines = [line.split() for line in data[:end].splitlines()]
    ascii = any(words[:1] == [b"format"] and b"ascii" in words for words in lines)
    declared = {words[1]: int(words[2]) for words in lines
                if len(words) == 3 and words[0] == b"element" and words[2].isdigit()}
    if declared.get(b"face", 0) > max_triangles:
        raise LimitError(f"{declared[b'face']} triangles is over this service's limit of "
                         f"{max_triangles}")
    for name, count in declared.items():
        if count > vertex_limit(max_triangles):
            raise LimitError(f"PLY element '{name.decode(errors='replace')}' declares {count} "
                             f"rows, over this service's limit of {vertex_limit(max_triangles)}")
    rows = sum(declared.values())
    if not ascii:
        return
    if rows > PLY_MAX_ROWS:
        raise LimitError(f"ASCII PLY declaring {rows} rows is over this service's limit of "
                         f"{PLY_MAX_ROWS}{TEXT_HINT}")
    body = data[end:]
    breaks = sum(body.count(sep) for sep in TEXT_SEPARATORS[2:])
    # Each row is a line; CRLF counts twice, and a few blank lines at the end are harmless.
    if breaks > 2 * rows + 64:
        raise LimitError(f"ASCII PLY has {breaks} line breaks after its header, which declares "
                         f"{rows} rows: over this service's limit of two a row")
    _text_fields(body, "ASCII PLY")


def _gltf(data: bytes, fmt: str, max_triangles: int) -> bytes:
    if fmt == "gltf":
        header = _json(data)
        if header is None:
            return data
        bin_length = 0
    else:
        found = _glb_chunks(data)
        if found is None:
            return data
        header, json_end, bin_length = found
    check_gltf_header(header, bin_length, vertex_limit(max_triangles), max_triangles)
    if "images" not in header:
        return data
    del header["images"]  # not by trimesh: a film's textures are read by scene.gltf_film
    text = json.dumps(header, separators=(",", ":")).encode()
    if fmt == "gltf":
        return text
    text += b" " * (-len(text) % 4)
    rest = data[json_end:]
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + rest
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def _json(data: bytes | memoryview) -> Any:
    """The parsed JSON, None where trimesh's own error will say what is wrong."""
    try:
        return json.loads(bytes(data))
    except RecursionError:
        raise LimitError("glTF JSON nested too deeply (arrays or objects within each other "
                         "past this service's parser depth limit)") from None
    except ValueError:
        return None


def _glb_chunks(data: bytes) -> tuple[dict[str, Any], int, int] | None:
    """(header, end of the JSON chunk, length of the BIN chunk), or None if not readable."""
    if len(data) < 20:
        return None
    json_length, kind = struct.unpack_from("<I4s", data, 12)
    json_end = 20 + json_length
    if kind != b"JSON" or json_end > len(data):
        return None
    header = _json(memoryview(data)[20:json_end])
    if not isinstance(header, dict):
        return None
    bin_length = 0
    if json_end + 8 <= len(data):
        length, kind = struct.unpack_from("<I4s", data, json_end)
        if kind == b"BIN\0":
            bin_length = min(length, len(data) - json_end - 8)
    return header, json_end, bin_length
