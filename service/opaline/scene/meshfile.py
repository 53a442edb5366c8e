"""Meshes from files (glTF/GLB, OBJ, PLY, STL), read with trimesh and checked before use.

Files come from users, so everything that can be wrong is a ``MeshError``
with a message fit for an HTTP 4xx: not a mesh, truncated or malformed, no
triangles, non-finite vertices, indices out of range, too many triangles.
The format comes from the bytes (uploads have no name), the extension only
breaking ties. Loading runs in the render worker processes only: trimesh's
parsers are the riskiest code that ever sees a request, and a worker that
crashes on one is replaced while the HTTP process answers on.

The mesh keeps its own coordinates (the camera frames its bounds); normals are
area-weighted and smooth across split vertices (``normals.vertex_normals``); tangents
are ``tangents.tangent_frame``.
"""

from __future__ import annotations

import gc
import importlib
import io
import re
from collections import OrderedDict
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

import numpy as np

from opaline.scene import meshlimits
from opaline.scene import tangents as tangent_fields
from opaline.scene.gltf_film import check_film_textures
from opaline.scene.mesh import Mesh, make_mesh
from opaline.scene.normals import vertex_normals
from opaline.scene.parse_memory import parse_ceiling, parse_headroom

if TYPE_CHECKING:
    import trimesh

FORMATS = ("glb", "gltf", "obj", "ply", "stl")
DEFAULT_MAX_TRIANGLES = 2_000_000
CACHED_MESHES = 4  # loaded meshes a worker keeps; the GPU copies have their own LRU


class MeshSummary(TypedDict):
    """What a check of an upload answers (as JSON): the file as the renderer reads it."""

    format: str
    triangles: int
    vertices: int
    uvs: bool
    tangents: str
    bounds: list[list[float]]  # [min xyz, max xyz] of the vertices the triangles use


OBJ_LINE = re.compile(rb"^[ \t]*(v|vt|vn|f|o|g|s|mtllib|usemtl)[ \t]", re.MULTILINE)


class MeshError(ValueError):
    """The file is not a mesh this service can draw; the message says why (HTTP 422)."""


def sniff(data: bytes, suffix: str = "") -> str:
    """The format of a mesh file from its first bytes; MeshError if it is none of them."""
    if data[:4] == b"glTF":
        return "glb"
    head = data[:4096].lstrip()
    if head.startswith(b"ply"):
        return "ply"
    if head.startswith(b"{"):
        return "gltf"
    # Binary STL: an 80-byte header, a triangle count and 50 bytes per triangle. Its
    # header may start with "solid" too, so the size decides before the keyword does.
    if len(data) >= 84 and 84 + 50 * int.from_bytes(data[80:84], "little") == len(data):
        return "stl"
    if head[:5].lower() == b"solid":
        return "stl"
    if suffix.lstrip(".").lower() == "obj" or OBJ_LINE.search(head):
        return "obj"
    raise MeshError("not a mesh: expected glTF/GLB, OBJ, PLY or STL "
                    f"(the file starts with {data[:16]!r})")


def _parse(data: bytes, fmt: str) -> trimesh.Trimesh:
    import trimesh  # imported here: only render workers ever parse a mesh

    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=fmt, force="mesh", process=False)
    except (MeshError, MemoryError):  # MemoryError: the parse ceiling, answered by the loader
        raise
    except Exception as exc:  # each parser fails in its own way on bad bytes
        raise MeshError(f"malformed or truncated {fmt.upper()} file: "
                        f"{type(exc).__name__}: {exc}"[:400]) from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshError(f"{fmt.upper()} file has no triangles")
    if fmt == "stl" and np.all(np.isfinite(loaded.vertices)):
        loaded.merge_vertices()  # STL repeats each corner per triangle: share them to smooth
    return loaded


def _uvs(loaded: trimesh.Trimesh, count: int) -> np.ndarray | None:
    uv = getattr(loaded.visual, "uv", None) if getattr(loaded.visual, "kind", None) else None
    if uv is None:
        return None
    uv = np.asarray(uv, dtype=np.float64)
    if uv.shape != (count, 2) or not np.all(np.isfinite(uv)):
        return None
    return uv


def parse_mesh(data: bytes, suffix: str = "", field: str = "auto",
               axis: Sequence[float] = (0.0, 1.0, 0.0),
               max_triangles: int = DEFAULT_MAX_TRIANGLES) -> tuple[Mesh, MeshSummary]:
    """A renderable ``Mesh`` and a summary (format, counts, bounds, tangent field used)."""
    data, fmt = admit(data, suffix, max_triangles)
    return build_mesh(data, fmt, field, axis, max_triangles)


def admit(data: bytes, suffix: str = "",
          max_triangles: int = DEFAULT_MAX_TRIANGLES) -> tuple[bytes, str]:
    """The bytes to parse and their format, once the cheap checks (the format, a film's
    textures, the counts the file declares) pass: MeshError on any, before trimesh."""
    if not data:
        raise MeshError("empty file: expected a glTF/GLB, OBJ, PLY or STL mesh")
    fmt = sniff(data, suffix)
    if fmt == "glb":  # a film's textures are drawn and exported with the mesh
        try:
            check_film_textures(data)
        except ValueError as exc:
            raise MeshError(str(exc)) from None
    try:
        data = meshlimits.check(data, fmt, max_triangles)  # (a .glb's images left out)
    except meshlimits.LimitError as exc:
        raise MeshError(str(exc)) from None
    return data, fmt


def build_mesh(data: bytes, fmt: str, field: str = "auto",
               axis: Sequence[float] = (0.0, 1.0, 0.0),
               max_triangles: int = DEFAULT_MAX_TRIANGLES, up: str = "y") -> tuple[Mesh, MeshSummary]:
    """``parse_mesh`` of bytes that ``admit`` passed: trimesh's parse, then the checks of
    what it built (counts, indices, finite and drawable coordinates, some area). A Z-up
    file (``up`` "z") is turned a quarter about x, (x, y, z) → (x, z, −y), a rotation (it
    keeps the winding), so that its +z is up before its normals, tangents and bounds."""
    loaded = _parse(data, fmt)
    try:
        return _checked_mesh(loaded, fmt, field, axis, max_triangles, up)
    finally:
        # trimesh's objects hold reference cycles (its caches), so a parse's intermediates
        # waited for the collector: ~300 MB of a 2M-triangle scan, which took its worker
        # past WORKER_MAX_RSS_MB, recycled after every render of it, each reading it again.
        del loaded
        gc.collect()


def _checked_mesh(loaded: trimesh.Trimesh, fmt: str, field: str, axis: Sequence[float],
                  max_triangles: int, up: str) -> tuple[Mesh, MeshSummary]:
    faces = np.asarray(loaded.faces, dtype=np.int64)
    positions = np.asarray(loaded.vertices, dtype=np.float64)
    if up == "z":
        positions = np.stack([positions[:, 0], positions[:, 2], -positions[:, 1]], axis=1)
    if len(faces) > max_triangles:
        raise MeshError(f"{len(faces)} triangles is over this service's limit of {max_triangles}")
    if faces.min() < 0 or faces.max() >= len(positions):
        raise MeshError(f"triangle indices out of range (the file has {len(positions)} vertices)")
    if not np.all(np.isfinite(positions)):
        bad = int(np.count_nonzero(~np.all(np.isfinite(positions), axis=1)))
        raise MeshError(f"{bad} vertices have NaN or infinite coordinates")
    used = positions[np.unique(faces)]
    if np.abs(used).max() > 1e15:
        raise MeshError("vertex coordinates beyond ±1e15 cannot be drawn in float32")
    areas = np.linalg.norm(np.cross(positions[faces[:, 1]] - positions[faces[:, 0]],
                                    positions[faces[:, 2]] - positions[faces[:, 0]]), axis=1)
    if not np.any(areas > 0.0):
        raise MeshError("every triangle has zero area")
    normals = vertex_normals(positions, faces)
    uvs = _uvs(loaded, len(positions))
    try:
        tangents, used_field = tangent_fields.tangent_frame(positions, normals, uvs, faces,
                                                            field, axis)
    except ValueError as exc:
        raise MeshError(str(exc)) from None
    lo, hi = used.min(axis=0), used.max(axis=0)
    mesh = make_mesh(positions, normals, tangents,
                     uvs if uvs is not None else np.zeros((len(positions), 2)), faces)
    summary: MeshSummary = {"format": fmt, "triangles": len(faces), "vertices": len(positions),
               "uvs": uvs is not None, "tangents": used_field,
               "bounds": [lo.tolist(), hi.tolist()]}
    return mesh, summary


# (path, size, mtime, field, axis, max_triangles, up) -> parse_mesh's answer
_loaded: OrderedDict[tuple[str, int, int, str, tuple[float, ...], int, str],
                    tuple[Mesh, MeshSummary]] = OrderedDict()


def load_mesh_file(path: str | Path, field: str = "auto",
                   axis: Sequence[float] = (0.0, 1.0, 0.0),
                   max_triangles: int = DEFAULT_MAX_TRIANGLES,
                   up: str = "y") -> tuple[Mesh, MeshSummary]:
    """``parse_mesh`` of a file, the last few kept (keyed by path, size and mtime)."""
    path = Path(path)
    try:
        stat = path.stat()
        key = (str(path), stat.st_size, stat.st_mtime_ns, field, tuple(axis), max_triangles, up)
        if key in _loaded:
            _loaded.move_to_end(key)
            return _loaded[key]
        data = path.read_bytes()
    except OSError as exc:
        raise MeshError(f"cannot read mesh {path.name}: {exc.strerror or exc}") from None
    try:
        with parse_ceiling():
            data, fmt = admit(data, path.suffix, max_triangles)
        # The parser's imports (trimesh pulls in scipy, ~170 MB) outside the ceiling, so the
        # headroom bounds the file's data alone (a fresh worker importing under a small one
        # failed with SystemError), and only once the cheap checks pass: a worker that only
        # ever refuses files never grows by them.
        importlib.import_module("trimesh")
        with parse_ceiling():
            found = build_mesh(data, fmt, field, axis, max_triangles, up)
    except MemoryError:
        headroom = (parse_headroom() or 0) >> 20
        raise MeshError(f"mesh {path.name} needs more than {headroom} MB to read, over this "
                        "service's limit; send fewer triangles, or as GLB or binary PLY") from None
    except MeshError as exc:  # the file's own fault, said with its name (a CLI user's --mesh)
        raise MeshError(f"mesh {path.name}: {exc}") from None
    _loaded[key] = found
    while len(_loaded) > CACHED_MESHES:
        _loaded.popitem(last=False)
    return found


def mesh_file(path: str, digest: str = "", tangent_field: str = "auto",
              tangent_axis: Sequence[float] = (0.0, 1.0, 0.0),
              max_triangles: int = DEFAULT_MAX_TRIANGLES, up: str = "y") -> Mesh:
    """The geometry generator ``file``: ``digest`` is unused here but names the content in
    the preset's scene key, so a changed file never draws from a stale GPU copy."""
    return load_mesh_file(path, tangent_field, tuple(tangent_axis), max_triangles, up)[0]
