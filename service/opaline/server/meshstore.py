"""Uploaded meshes on disk, under their content hash, least recently used evicted first.

The HTTP process only stores and hashes bytes here: it never parses a mesh
(a render worker does, ``workers.mesh_tasks.MeshCheckTask``). A mesh is named
by the first 32 hex digits of its SHA-256, so the same file uploaded twice is
stored once and keeps its id; a request may also name a file of the folder
``OPALINE_MESHES_DIR`` by its file name.

With a shared state store (``OPALINE_STATE_URL``) the store holds every upload, under
its budget, and this folder is each replica's copy of what it has used (workers read
files): a mesh uploaded through one replica renders on any other.
"""

from __future__ import annotations

import hashlib
import os
import re
import threading
import time
import weakref
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path

from opaline import scratch
from opaline.digests import known_file_digest
from opaline.errors import PublicError
from opaline.lru import BudgetLRU
from opaline.model.meshes import mesh_preset
from opaline.model.presets import Preset
from opaline.model.scene_fields import SceneFields
from opaline.server.statestore import StateStore, StoreUnavailable
from opaline.settings import Settings

MESH_ID = re.compile(r"^[0-9a-f]{32}$")
SUFFIX = ".mesh"  # the format is in the bytes; the worker sniffs it
TOUCH_PAUSE_S = 5.0
SUMMARIES_KEPT = 1024


class UnknownMesh(PublicError, KeyError):
    status, reason = 404, "unknown_mesh"

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(name)

    def __str__(self) -> str:
        return (f"mesh={self.name!r} is not stored on this service (it may have been evicted): "
                "upload it with POST /v1/meshes and use the id it answers")


class InvalidMesh(PublicError, ValueError):
    """The uploaded bytes are not a mesh this service reads, or one over its limits (422
    ``invalid_mesh``: the OpenAPI schema of the body, any binary, cannot say which are)."""

    status, reason = 422, "invalid_mesh"


class MeshTooLarge(PublicError, ValueError):
    """The upload is over ``mesh_max_bytes`` (413)."""

    status, reason = 413, "too_large"


class MeshStore:
    """Files ``<id>.mesh`` in one folder, their total bytes under a budget."""

    def __init__(self, settings: Settings, shared: StateStore | None = None) -> None:
        self.shared = shared if shared is not None and shared.shared else None
        root = settings.mesh_store_dir
        self._closer: Callable[[], object]
        if root is None:  # a private folder, removed at shutdown (``close``) or at exit;
            # one a killed run left is swept here, by the next store to start
            scratch.sweep("meshes")
            lock, root = scratch.owned_dir("meshes")
            self._closer = weakref.finalize(self, scratch.release, lock, root)
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        if settings.mesh_store_dir is not None:
            self._closer = weakref.finalize(self, scratch.sweep, "upload", folder=self.root)
            scratch.sweep("upload", folder=self.root)  # uploads a killed run was receiving
        self.budget = settings.mesh_store_bytes
        self.max_file = settings.mesh_max_bytes
        self.folder = settings.meshes_dir
        self._lock = threading.Lock()
        self._sizes: OrderedDict[str, int] = OrderedDict()
        self.evictions = 0
        self._touch_after = 0.0
        # What the check answered of each (JSON, ~200 bytes), for GET /v1/meshes/{id}.
        self.summaries: BudgetLRU[str, bytes] = BudgetLRU(SUMMARIES_KEPT, SUMMARIES_KEPT * 1024)
        # What an earlier run left, oldest first, so restarts keep the LRU order.
        found = sorted(self.root.glob("*" + SUFFIX), key=lambda p: p.stat().st_mtime_ns)
        for path in found:
            if MESH_ID.match(path.stem):
                self._sizes[path.stem] = path.stat().st_size
        self._evict()

    @property
    def size_bytes(self) -> int:
        return sum(self._sizes.values())

    def path_of(self, mesh_id: str) -> Path:
        return self.root / f"{mesh_id}{SUFFIX}"

    def close(self) -> None:
        """Remove the private folder (or, in a configured one, uploads still arriving): the
        lifespan's shutdown calls this, since a signal's exit skips ``atexit``."""
        self._closer()

    def put(self, data: bytes) -> str:
        """Store ``data`` (atomically) and answer its id; the newest is never evicted."""
        if len(data) > self.max_file:
            raise MeshTooLarge(f"mesh file of {len(data)} bytes is over this service's limit "
                               f"of {self.max_file} bytes")
        mesh_id = hashlib.sha256(data).hexdigest()[:32]
        if self.shared is not None:  # first: an id is answered only once every replica has it
            self.shared.put(f"mesh:{mesh_id}", data)
        self._keep(mesh_id, data)
        return mesh_id

    def put_file(self, path: Path, mesh_id: str) -> str:
        """Store the file at ``path`` (an upload spooled in ``root``, moved, not copied) as
        ``mesh_id``, the digest of its bytes; the newest is never evicted."""
        if self.shared is not None:  # the store's interface takes bytes: one copy, briefly
            self.shared.put(f"mesh:{mesh_id}", path.read_bytes())
        with self._lock:
            if mesh_id not in self._sizes:
                size = path.stat().st_size
                os.replace(path, self.path_of(mesh_id))
                self._sizes[mesh_id] = size
            self._touch(mesh_id)
            self._evict(keep=mesh_id)
        return mesh_id

    def _keep(self, mesh_id: str, data: bytes) -> None:
        fd, tmp = scratch.owned_file("upload", ".part", self.root)
        try:
            with os.fdopen(os.dup(fd), "wb") as stream:
                stream.write(data)
            with self._lock:
                if mesh_id not in self._sizes:
                    os.replace(tmp, self.path_of(mesh_id))
                    self._sizes[mesh_id] = len(data)
                self._touch(mesh_id)
                self._evict(keep=mesh_id)
        finally:
            scratch.release(fd, tmp)

    def resolve(self, name: str) -> tuple[Path, str]:
        """The file and content digest a request's ``mesh`` names; UnknownMesh if none."""
        if MESH_ID.match(name):
            with self._lock:
                if name in self._sizes and self.path_of(name).is_file():
                    self._touch(name)
                    return self._used(name), name
            if self.shared is not None and (data := self.shared.get(f"mesh:{name}")):
                self._keep(name, data)
                return self.path_of(name), name
        elif self.folder is not None and "/" not in name and "\\" not in name \
                and not name.startswith("."):
            path = Path(self.folder) / name
            try:
                found = path.is_file()
            except (OSError, ValueError):  # a name no file can have (over 255 bytes, a NUL)
                found = False
            if found:
                return path, known_file_digest(path)
        raise UnknownMesh(name)

    def _used(self, mesh_id: str) -> Path:
        """The local copy; the shared store hears of the use (its LRU order), if it answers:
        a copy here renders while the store is down, and does not wait on it again for a
        while (each try may take the store's timeout)."""
        if self.shared is not None and time.monotonic() >= self._touch_after:
            try:
                self.shared.touch(f"mesh:{mesh_id}")
            except StoreUnavailable:
                self._touch_after = time.monotonic() + TOUCH_PAUSE_S
        return self.path_of(mesh_id)

    def _touch(self, mesh_id: str) -> None:
        self._sizes.move_to_end(mesh_id)
        try:
            os.utime(self.path_of(mesh_id))  # the order survives a restart
        except OSError:
            pass

    def _evict(self, keep: str | None = None) -> None:
        while self.size_bytes > self.budget and len(self._sizes) > (1 if keep else 0):
            oldest = next(iter(self._sizes))
            if oldest == keep:
                self._sizes.move_to_end(oldest)
                continue
            del self._sizes[oldest]
            self.path_of(oldest).unlink(missing_ok=True)
            self.evictions += 1

    def preset(self, params: SceneFields, base: Preset, max_triangles: int) -> Preset:
        """``base`` drawing the mesh ``params.mesh`` names (UnknownMesh, 404, if none)."""
        assert params.mesh is not None
        path, digest = self.resolve(params.mesh)
        return mesh_preset(base, path, digest, params, max_triangles)
