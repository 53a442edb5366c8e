"""An upload's body onto disk as it arrives: never whole in the HTTP process's memory.

Each chunk the server hands over (uvicorn keeps at most about 64 KiB of a body
unread before it stops reading the socket) is hashed and written to a locked
spool file in the mesh store's folder, then the finished file is moved into
place under its digest once a worker has checked it (``server/mesh_routes.py``):
until then no render can name it. What one upload in flight holds is a chunk and the
hash's state, whatever the file's size (``tests/server/test_upload_memory.py``
measures 16 at once); the size limit is enforced as bytes arrive (``BodyLimit``
answers 413 for the route; the spool refuses past the store's own limit too).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

from starlette.requests import Request

from opaline import scratch
from opaline.server.meshstore import InvalidMesh, MeshStore, MeshTooLarge

EMPTY = ("empty body: send the mesh file (glTF/GLB, OBJ, PLY or STL) as the request body")


@asynccontextmanager
async def spooled_mesh(request: Request, store: MeshStore) -> AsyncIterator[tuple[Path, str]]:
    """Spool the request's body into ``store``'s folder; the spool file and the mesh's id.
    The file is the store's only once ``store.put_file`` moves it in (after its check);
    otherwise it is removed on the way out, whatever ended the request."""
    fd, path = scratch.owned_file("upload", ".part", store.root)
    digest, size = hashlib.sha256(), 0
    try:
        async for chunk in request.stream():
            size += len(chunk)
            if size > store.max_file:
                raise MeshTooLarge(f"mesh file over this service's limit of "
                                   f"{store.max_file} bytes")
            digest.update(chunk)
            view = memoryview(chunk)
            while view:  # a regular file takes it whole; the loop is for the exception
                view = view[os.write(fd, view):]
        if not size:
            raise InvalidMesh(EMPTY)
        yield Path(path), digest.hexdigest()[:32]
    finally:
        scratch.release(fd, path)  # the spool if it was not moved into place; the lock
