"""A glTF header's declared sizes checked against the bytes that back them and the limits.

Every accessor must fit in its buffer view and every view in its buffer's real
length (so no count can make trimesh allocate what the file does not hold); an
accessor without a buffer (trimesh fills it with zeros) is held to the vertex
limit; nodes, primitives and the triangles drawn once every instance is counted
are bounded, as trimesh copies each instance when it flattens the scene.
"""

from __future__ import annotations

from typing import Any

MAX_NODES = 1000  # trimesh flattens a scene at about 0.7 ms a node instance
MAX_PRIMITIVES = 1000
MAX_ACCESSORS = 10_000
COMPONENT_BYTES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
TYPE_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9,
                   "MAT4": 16}
TRIANGLES, STRIP, FAN = 4, 5, 6


class LimitError(ValueError):
    """A declared size the file cannot back or the service does not allow (raised as
    ``MeshError`` by meshfile)."""


def check_gltf_header(header: dict[str, Any], bin_length: int, max_elements: int,
                      max_triangles: int) -> None:
    try:
        views = _views(header, _buffer_lengths(header, bin_length))
        counts = [_accessor(i, a, views, max_elements)
                  for i, a in enumerate(_list(header, "accessors", MAX_ACCESSORS))]
        per_mesh = [_mesh_triangles(mesh, counts) for mesh in header.get("meshes", [])]
        drawn = _instanced_triangles(header, per_mesh)
    except (TypeError, KeyError, IndexError, AttributeError) as exc:
        raise LimitError(f"malformed glTF header: {type(exc).__name__}: {exc}"[:300]) from None
    if drawn > max_triangles:
        raise LimitError(f"the scene draws {drawn} triangles once its node instances are "
                             f"counted, over this service's limit of {max_triangles}")


def _list(header: dict[str, Any], key: str, limit: int) -> list[Any]:
    found = header.get(key, [])
    if not isinstance(found, list):
        raise TypeError(f"'{key}' is not a list")
    if len(found) > limit:
        raise LimitError(f"glTF with {len(found)} {key} is over this service's limit of "
                             f"{limit}")
    return found


def _buffer_lengths(header: dict[str, Any], bin_length: int) -> list[int]:
    """Bytes each buffer really has: a data URI's decoded size, the GLB's BIN chunk for the
    first buffer without a URI, nothing for the rest (trimesh has no files to resolve)."""
    lengths, bin_left = [], bin_length
    for buffer in _list(header, "buffers", MAX_ACCESSORS):
        uri = buffer.get("uri")
        if isinstance(uri, str) and uri.startswith("data:") and "," in uri:
            meta, payload = uri.split(",", 1)
            size = (len(payload) * 3 // 4 - payload[-2:].count("=")) if meta.endswith(
                ";base64") else len(payload)
            lengths.append(size)
        elif uri is None:
            lengths.append(bin_left)
            bin_left = 0
        else:
            lengths.append(0)
    return lengths


def _int(value: Any, what: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise LimitError(f"{what} is {value!r}, not a count")
    return value


def _views(header: dict[str, Any], buffers: list[int]) -> list[tuple[int, int]]:
    """(byteLength, byteStride or 0) of each buffer view, checked against its buffer."""
    found = []
    for i, view in enumerate(_list(header, "bufferViews", MAX_ACCESSORS)):
        start = _int(view.get("byteOffset", 0), f"bufferView {i}'s byteOffset")
        length = _int(view["byteLength"], f"bufferView {i}'s byteLength")
        buffer = _int(view["buffer"], f"bufferView {i}'s buffer")
        real = buffers[buffer] if buffer < len(buffers) else 0
        if start + length > real:
            raise LimitError(f"bufferView {i} claims bytes {start}-{start + length} of "
                                 f"buffer {buffer}, which holds {real}")
        found.append((length, _int(view.get("byteStride", 0), f"bufferView {i}'s byteStride")))
    return found


def _accessor(i: int, accessor: dict[str, Any], views: list[tuple[int, int]],
              max_elements: int) -> int:
    count = _int(accessor["count"], f"accessor {i}'s count")
    if count > max_elements:
        raise LimitError(f"accessor {i} declares {count} elements, over this service's "
                             f"limit of {max_elements} (three per allowed triangle)")
    sparse = accessor.get("sparse")
    if isinstance(sparse, dict) and _int(sparse.get("count", 0), "a sparse count") > max_elements:
        raise LimitError(f"accessor {i}'s sparse part declares {sparse['count']} elements, "
                             f"over this service's limit of {max_elements}")
    if "bufferView" not in accessor or count == 0:
        return count
    item = COMPONENT_BYTES.get(accessor["componentType"], 0) * TYPE_COMPONENTS.get(
        accessor["type"], 0)
    if item == 0:
        raise LimitError(f"accessor {i} has an unknown componentType or type")
    length, stride = views[_int(accessor["bufferView"], f"accessor {i}'s bufferView")]
    start = _int(accessor.get("byteOffset", 0), f"accessor {i}'s byteOffset")
    need = start + (count - 1) * (stride or item) + item
    if need > length:
        raise LimitError(f"accessor {i} needs {need} bytes of its bufferView, which has "
                             f"{length}")
    return count


def _mesh_triangles(mesh: dict[str, Any], counts: list[int]) -> int:
    total = 0
    for primitive in mesh.get("primitives", []):
        mode = primitive.get("mode", TRIANGLES)
        index = primitive.get("indices", primitive.get("attributes", {}).get("POSITION"))
        n = counts[index] if isinstance(index, int) and 0 <= index < len(counts) else 0
        total += n // 3 if mode == TRIANGLES else max(n - 2, 0) if mode in (STRIP, FAN) else 0
    return total


def _instanced_triangles(header: dict[str, Any], per_mesh: list[int]) -> int:
    """Triangles of the default scene, walked as trimesh does (each parent-child edge once)."""
    nodes = _list(header, "nodes", MAX_NODES)
    if sum(len(m.get("primitives", [])) for m in header.get("meshes", [])) > MAX_PRIMITIVES:
        raise LimitError(f"glTF with more than {MAX_PRIMITIVES} primitives is over this "
                             "service's limit")
    scenes = header.get("scenes", [])
    if not scenes:
        return 0
    roots = scenes[header.get("scene", 0)].get("nodes", [])
    queue = [(-1, root) for root in roots]
    seen: set[tuple[int, int]] = set()
    drawn = 0
    while queue:
        edge = queue.pop()
        if edge in seen:
            continue
        seen.add(edge)
        if len(seen) > MAX_NODES:
            raise LimitError(f"the scene instances nodes more than {MAX_NODES} times, over "
                                 "this service's limit")
        node = nodes[edge[1]]
        queue.extend((edge[1], child) for child in node.get("children", []))
        if "mesh" in node:
            drawn += per_mesh[node["mesh"]]
    return drawn
