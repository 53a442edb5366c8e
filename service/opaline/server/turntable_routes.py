"""Turntables over HTTP: POST /v1/turntables starts one, GET says how far it is, and
GET .../result answers the animation.

Each frame is an ordinary render job (cached, deduplicated, admitted, run by
the workers), at most one per worker at a time so a turntable never fills
the queue that other requests need; a worker then encodes the frames. The
cost budget covers all frames. Progress is the count of finished frames.
"""

from __future__ import annotations

import asyncio
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Request
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel

from opaline.model.presets import get_preset
from opaline.model.request import content_key, resolve
from opaline.model.turntable import TurntableRequest, check_turntable_cost, frame_jobs
from opaline.output.animation import EXTENSIONS, MEDIA_TYPES
from opaline.server.errors import ERROR_RESPONSES
from opaline.server.render_routes import check_limits
from opaline.server.service import Service, get_service
from opaline.workers.animation_task import AnimationTask
from opaline.workers.tasks import ImageTask

ServiceDep = Annotated[Service, Depends(get_service)]
router = APIRouter()
KEPT = 64  # finished or running turntables remembered (oldest forgotten first)


class TurntableStatus(BaseModel):
    id: str
    state: str  # running, done, failed
    done: int
    frames: int
    error: str | None = None
    result: str


@dataclass
class Turntable:
    id: str
    frames: int
    fmt: str
    done: int = 0
    state: str = "running"
    error: str | None = None
    data: bytes | None = None
    task: Any = field(default=None, repr=False)

    def status(self) -> TurntableStatus:
        return TurntableStatus(id=self.id, state=self.state, done=self.done, frames=self.frames,
                               error=self.error, result=f"/v1/turntables/{self.id}/result")


def registry(request: Request) -> OrderedDict[str, Turntable]:
    state = request.app.state
    if not hasattr(state, "turntables"):
        state.turntables = OrderedDict()
    return state.turntables


async def run(svc: Service, entry: Turntable, tasks: list[tuple[str, ImageTask]],
              fps: int) -> None:
    frames: list[bytes | None] = [None] * len(tasks)
    lanes = asyncio.Semaphore(svc.settings.workers)

    async def one(index: int, key: str, task: ImageTask) -> None:
        async with lanes:
            frames[index] = await svc.pool.render(key, task, timeout=svc.wait_s)
            entry.done += 1

    try:
        await asyncio.gather(*(one(i, key, task) for i, (key, task) in enumerate(tasks)))
        encode = AnimationTask(tuple(f for f in frames if f is not None), entry.fmt, fps)
        entry.data = await svc.pool.render(f"animation:{entry.id}", encode, timeout=svc.wait_s)
        entry.state = "done"
    except Exception as exc:  # each failure's public message; the turntable is marked failed
        entry.state, entry.error = "failed", f"{type(exc).__name__}: {exc}"


@router.post("/v1/turntables", tags=["turntables"], status_code=202, responses=ERROR_RESPONSES,
             summary="Start a turntable: N frames around the object, then WebP, GIF or MP4")
async def turntable_post(body: TurntableRequest, request: Request,
                         svc: ServiceDep) -> TurntableStatus:
    still = body.still()
    preset = get_preset(still.preset)
    if still.mesh is not None:
        preset = request.app.state.meshes.preset(still, preset, svc.settings.mesh_max_triangles)
    job = resolve(still, preset)
    check_limits(job, svc.settings)
    check_turntable_cost(job, body.frames, svc.settings.cost_budget)
    jobs = frame_jobs(job, preset, body.frames)
    tasks = [(j.cache_key(preset.scene_key()), ImageTask(j, preset)) for j in jobs]
    key = content_key({"frames": [k for k, _ in tasks], "fmt": body.animation, "fps": body.fps})
    found = registry(request)
    entry = found.get(key)
    if entry is None or entry.state == "failed":
        entry = found[key] = Turntable(key, body.frames, body.animation)
        entry.task = asyncio.create_task(run(svc, entry, tasks, body.fps))
        while len(found) > KEPT:
            oldest = found.popitem(last=False)[1]
            if oldest.task is not None and oldest.state == "running":
                oldest.task.cancel()
    return entry.status()


def _entry(request: Request, turntable_id: str) -> Turntable | None:
    return registry(request).get(turntable_id)


@router.get("/v1/turntables/{turntable_id}", tags=["turntables"],
            summary="A turntable's progress: frames done of frames")
async def turntable_get(turntable_id: str, request: Request) -> TurntableStatus:
    entry = _entry(request, turntable_id)
    if entry is None:
        return JSONResponse({"detail": f"turntable {turntable_id!r} is not known"}, 404)
    return entry.status()


@router.get("/v1/turntables/{turntable_id}/result", tags=["turntables"],
            response_class=Response, summary="The finished animation (409 while it renders)")
async def turntable_result(turntable_id: str, request: Request) -> Response:
    entry = _entry(request, turntable_id)
    if entry is None:
        return JSONResponse({"detail": f"turntable {turntable_id!r} is not known"}, 404)
    if entry.state != "done" or entry.data is None:
        detail = entry.error or f"still rendering: {entry.done} of {entry.frames} frames done"
        return JSONResponse({"detail": detail, **entry.status().model_dump()},
                            409 if entry.state == "running" else 500)
    headers = {"Content-Disposition": f'inline; filename="turntable{EXTENSIONS[entry.fmt]}"'}
    return Response(entry.data, media_type=MEDIA_TYPES[entry.fmt], headers=headers)
