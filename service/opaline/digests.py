"""Content hashes of files: what names an uploaded mesh, a mesh of the meshes folder and an
environment file in keys, so that an edited file draws anew."""

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
