"""POST /v1/meshes: a user's mesh file in, its id out, checked by a render worker;
GET /v1/meshes/{id}: what the upload answered, again.

The HTTP process spools and hashes the bytes; the check lane's worker
(``check_lane``, never in front of renders) parses and validates them
(``workers.mesh_tasks``), and only then does the store (``meshstore``) keep
them, so the answer is 201 with the mesh's summary, or 422 ``invalid_mesh``
saying what is wrong with the file (which is then not kept; the body's schema, any binary, cannot express what a
mesh is), or 413 for a file over ``OPALINE_MESH_MAX_BYTES``. Renders name the
id as ``mesh=<id>``; ``MeshStore.preset`` turns that into the preset the worker
draws. The 201 names ``/v1/meshes/<id>`` in ``Location``; that GET answers the summary
from this replica's memory of it or, on a replica that has not seen it, by checking the
file again (fetched from the shared store, as a render would).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fastapi import APIRouter, Request, Response
from pydantic import BaseModel, Field

from opaline.server.deps import ServiceDep
from opaline.server.errors import ERROR_RESPONSES, Problem
from opaline.server.mesh_upload import spooled_mesh
from opaline.server.meshstore import InvalidMesh
from opaline.server.render_routes import client_gone
from opaline.workers.errors import InvalidInput
from opaline.workers.mesh_tasks import MeshCheckTask

router = APIRouter()


class MeshInfo(BaseModel):
    id: str = Field(description="Name this mesh in render requests as mesh=<id>.")
    format: str = Field(description="glb, gltf, obj, ply or stl, as read from the bytes.")
    triangles: int
    vertices: int
    uvs: bool = Field(description="Whether the mesh has UV coordinates (tangents from them).")
    tangents: str = Field(description="The tangent field an 'auto' request gets.")
    bounds: list[list[float]] = Field(description="Lower and upper corner of its bounding box.")


MESH_RESPONSES: dict[int | str, dict[str, Any]] = {
    **ERROR_RESPONSES,
    413: {"model": Problem, "description": "The file is over the service's size limit."},
    422: {"model": Problem, "description": "error 'invalid_mesh': the body is empty, is not a "
                                           "glTF/GLB, OBJ, PLY or STL file, is malformed, or has "
                                           "more triangles than the service allows."},
}


UNKNOWN = {"model": Problem, "description": "error 'unknown_mesh': never uploaded, or evicted "
                                           "(upload it again: the id is its content's)."}


@router.post("/v1/meshes", tags=["meshes"], status_code=201, responses=MESH_RESPONSES,
             summary="Upload a mesh (glTF/GLB, OBJ, PLY or STL as the raw body)",
             openapi_extra={"requestBody": {"required": True, "content": {
                 "application/octet-stream": {"schema": {"type": "string",
                                                         "format": "binary"}}}}})
async def meshes_post(request: Request, response: Response, svc: ServiceDep) -> MeshInfo:
    store = svc.meshes
    # Streamed to disk, never whole in memory, and checked where it was spooled: the store
    # holds it only once the check passed, so no render parses it unchecked, and a check
    # that fails or never ran (killed, refused, waited out, the client gone) leaves the
    # store as it was (a copy of the same bytes stored earlier stays).
    async with spooled_mesh(request, store) as (spool, mesh_id):
        summary = await _checked(svc, request, spool, mesh_id)
        store.put_file(spool, mesh_id)
    store.summaries.put(mesh_id, summary, len(summary))
    response.headers["Location"] = f"/v1/meshes/{mesh_id}"
    return MeshInfo(id=mesh_id, **json.loads(summary))


@router.get("/v1/meshes/{mesh}", tags=["meshes"], responses={**ERROR_RESPONSES, 404: UNKNOWN},
            summary="A stored mesh's summary (what its upload answered)")
async def mesh_get(mesh: str, request: Request, svc: ServiceDep) -> MeshInfo:
    path, digest = svc.meshes.resolve(mesh)  # 404 unless stored (here or shared) or in the folder
    summary = svc.meshes.summaries.get(digest)
    if summary is None:
        summary = await _checked(svc, request, path, digest)
        svc.meshes.summaries.put(digest, summary, len(summary))
    return MeshInfo(id=mesh, **json.loads(summary))


async def _checked(svc: ServiceDep, request: Request, path: Path, digest: str) -> bytes:
    """The check lane's summary of the file at ``path`` (InvalidMesh, 422, if it is none)."""
    max_triangles = svc.settings.mesh_max_triangles
    task = MeshCheckTask(str(path), max_triangles)
    try:
        return await svc.checks.render(f"mesh-check:{digest}:{max_triangles}", task,
                                       timeout=svc.wait_s, gone=client_gone(request))
    except InvalidInput as exc:
        raise InvalidMesh(str(exc)) from None
