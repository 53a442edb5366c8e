"""Exports over HTTP: the material as GLSL (GET) and the mesh with its material as .glb
(POST), both written by a worker: only workers touch meshes and load GL modules."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Request
from fastapi.responses import Response

from opaline.model.params import RenderRequest
from opaline.model.request import content_key
from opaline.pipeline.prepare import prepare
from opaline.server.deps import ServiceDep
from opaline.server.errors import ERROR_RESPONSES, JSON_BODY_RESPONSES
from opaline.server.queries import RenderQuery, json_body, parse_body
from opaline.server.render_routes import BODY, RENDER_RESPONSES
from opaline.workers.export_task import GlbTask, GlslTask

router = APIRouter()


@router.get("/v1/export/glsl", tags=["export"], response_class=Response,
            responses={**ERROR_RESPONSES, 404: RENDER_RESPONSES[404]},
            summary="The material as one self-contained GLSL function (opaline_radiance)")
async def export_glsl_get(params: Annotated[RenderQuery, Query()], request: Request,
                          svc: ServiceDep) -> Response:
    job = prepare(params, svc.context).job
    key = content_key({"glsl": job.canonical()})
    data = await svc.pool.render(key, GlslTask(job.material, job.wavelengths),
                                 timeout=svc.wait_s)
    return Response(data, media_type="text/plain",
                    headers={"Content-Disposition": 'attachment; filename="opaline.glsl"'})


# Parsed strictly, as POST /v1/render's body ({"light_elevation": false} is refused).
@router.post("/v1/export/glb", tags=["export"], response_class=Response,
             responses={**ERROR_RESPONSES, **JSON_BODY_RESPONSES, 404: RENDER_RESPONSES[404]},
             openapi_extra=BODY,
             summary="The mesh with the material as glTF 2.0 binary (.glb)")
async def export_glb_post(request: Request, svc: ServiceDep) -> Response:
    body = parse_body(await json_body(request), RenderRequest)
    prepared = prepare(body, svc.context)
    preset, job = prepared.preset, prepared.job
    key = content_key({"glb": job.canonical(), "scene": preset.scene_key()})
    data = await svc.pool.render(key, GlbTask(preset, job.material, job.wavelengths),
                                 timeout=svc.wait_s)
    return Response(data, media_type="model/gltf-binary",
                    headers={"Content-Disposition": f'attachment; filename="{preset.name}.glb"'})
