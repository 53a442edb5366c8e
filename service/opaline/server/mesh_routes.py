"""POST /v1/meshes: a user's mesh file in, its id out, checked by a render worker.

The HTTP process spools and hashes the bytes; the check lane's worker
(``check_lane``, never in front of renders) parses and validates them
(``workers.mesh_tasks``), and only then does the store (``meshstore``) keep
them, so the answer is 201 with the mesh's summary, or 422 ``invalid_mesh``
saying what is wrong with the file (which is then not kept; the body's schema, any binary, cannot express what a
mesh is), or 413 for a file over ``OPALINE_MESH_MAX_BYTES``. Renders name the
id as ``mesh=<id>``; ``MeshStore.preset`` turns that into the preset the worker
draws.
"""

from __future__ import annotations

import json
from typing import Any

from fastapi import APIRouter, Request
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


@router.post("/v1/meshes", tags=["meshes"], status_code=201, responses=MESH_RESPONSES,
             summary="Upload a mesh (glTF/GLB, OBJ, PLY or STL as the raw body)",
             openapi_extra={"requestBody": {"required": True, "content": {
                 "application/octet-stream": {"schema": {"type": "string",
                                                         "format": "binary"}}}}})
async def meshes_post(request: Request, svc: ServiceDep) -> MeshInfo:
    store = svc.meshes
    max_triangles = svc.settings.mesh_max_triangles
    # Streamed to disk, never whole in memory, and checked where it was spooled: the store
    # holds it only once the check passed, so no render parses it unchecked, and a check
    # that fails or never ran (killed, refused, waited out, the client gone) leaves the
    # store as it was (a copy of the same bytes stored earlier stays).
    async with spooled_mesh(request, store) as (spool, mesh_id):
        task = MeshCheckTask(str(spool), max_triangles)
        try:
            summary = await svc.checks.render(f"mesh-check:{mesh_id}:{max_triangles}", task,
                                              timeout=svc.wait_s, gone=client_gone(request))
        except InvalidInput as exc:
            raise InvalidMesh(str(exc)) from None
        store.put_file(spool, mesh_id)
    return MeshInfo(id=mesh_id, **json.loads(summary))
