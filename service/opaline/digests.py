"""Content hashes of files: what names an uploaded mesh, a mesh of the meshes folder and an
environment file in keys, so that an edited file draws anew. A file named again and again
(a folder's mesh, a local mesh file, an environment) is hashed again only when its size
or time changes."""

from __future__ import annotations

import hashlib
from pathlib import Path


def file_digest(path: Path) -> str:
    """The first 32 hex digits of the file's SHA-256, read 1 MiB at a time."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for chunk in iter(lambda: stream.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()[:32]


_known: dict[tuple[str, int, int], str] = {}
KNOWN = 256  # files whose digest is kept; past that the memory starts over


def known_file_digest(path: Path) -> str:
    """``file_digest``, kept by the file's path, size and modification time."""
    stat = path.stat()
    key = (str(path), stat.st_size, stat.st_mtime_ns)
    if key not in _known:
        if len(_known) >= KNOWN:
            _known.clear()
        _known[key] = file_digest(path)
    return _known[key]
