"""Turntables over HTTP: POST /v1/turntables starts one, GET says how far it is, and
GET .../result answers the animation.

Each frame is an ordinary render job (cached, deduplicated, admitted, run by
the workers); a worker then encodes the frames. The cost budget covers all
frames. Progress is the count of finished frames.

Turntables must not crowd out single renders, nor fail because single renders
filled the queue for a moment: all running turntables share one frame lane per
worker (so they add at most one frame per worker to the work ahead), at most
``max_turntables`` run at once (one more is 429 ``busy`` with Retry-After), and
a frame refused as Overloaded waits and is submitted again until the
turntable's own deadline (one render deadline per frame, plus one wait).
Failures answer in the public shape: 404 ``unknown_turntable``, 409
``rendering``, and a failed turntable's result answers its failure's own
status (422 ``too_slow``, 503 ``deadline`` ...).
"""

from __future__ import annotations

import asyncio
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import Response
from pydantic import BaseModel

from opaline.model.request import content_key
from opaline.model.turntable import TurntableRequest, check_turntable_cost, frame_jobs
from opaline.output.animation import EXTENSIONS, MEDIA_TYPES
from opaline.pipeline.prepare import prepare
from opaline.server.deps import LanesDep, ServiceDep, TurntablesDep
from opaline.server.errors import (
    ERROR_RESPONSES,
    RETRY_AFTER,
    Busy,
    Problem,
    StillRendering,
    UnknownTurntable,
)
from opaline.server.queries import parse_body
from opaline.server.render_routes import RENDER_RESPONSES
from opaline.server.service import Service
from opaline.workers.animation_task import AnimationTask
from opaline.workers.errors import DeadlineExceeded, Overloaded, TooSlow
from opaline.workers.tasks import ImageTask

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
    failure: Exception | None = field(default=None, repr=False)
    task: Any = field(default=None, repr=False)

    def status(self) -> TurntableStatus:
        return TurntableStatus(id=self.id, state=self.state, done=self.done, frames=self.frames,
                               error=self.error, result=f"/v1/turntables/{self.id}/result")


async def patiently(svc: Service, key: str, task: Any, deadline: float) -> bytes:
    """A render that waits out a full queue (Overloaded) until ``deadline`` (loop time)."""
    loop = asyncio.get_running_loop()
    while True:
        try:
            return await svc.pool.render(key, task, timeout=svc.wait_s)
        except Overloaded as exc:
            left = deadline - loop.time()
            if left <= 0:
                raise DeadlineExceeded(f"the queue stayed full until the turntable's "
                                       f"deadline ({exc})") from None
            await asyncio.sleep(min(max(exc.retry_after_s, 0.05), left))


async def run(svc: Service, entry: Turntable, tasks: list[tuple[str, ImageTask]],
              fps: int, shared: asyncio.Semaphore) -> None:
    frames: list[bytes | None] = [None] * len(tasks)
    loop = asyncio.get_running_loop()
    deadline = loop.time() + len(tasks) * svc.settings.deadline_s + svc.wait_s

    async def one(index: int, key: str, task: ImageTask) -> None:
        async with shared:
            frames[index] = await patiently(svc, key, task, deadline)
            entry.done += 1

    try:
        await asyncio.gather(*(one(i, key, task) for i, (key, task) in enumerate(tasks)))
        encode = AnimationTask(tuple(f for f in frames if f is not None), entry.fmt, fps)
        entry.data = await patiently(svc, f"animation:{entry.id}", encode, deadline)
        entry.state = "done"
    except Exception as exc:  # kept: the result answers it as the public error it is
        entry.state, entry.error, entry.failure = "failed", f"{type(exc).__name__}: {exc}", exc


RENDER_404 = RENDER_RESPONSES[404]
BUSY = {"model": Problem, "headers": RETRY_AFTER,
        "description": "error 'busy': as many turntables as the service runs at once are "
                       "rendering; retry after Retry-After seconds."}
UNKNOWN = {"model": Problem, "description": "error 'unknown_turntable': never started here, "
                                            "or forgotten (the service keeps the latest 64)."}
RESULT_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The animation: animated WebP, GIF or MP4.",
          "content": {t: {"schema": {"type": "string", "format": "binary"}}
                      for t in MEDIA_TYPES.values()}},
    **ERROR_RESPONSES,
    404: UNKNOWN,
    409: {"model": Problem, "description": "error 'rendering': the frames are not all done yet; "
                                           "GET /v1/turntables/{id} tells how far it is."},
    422: {"model": Problem, "description": "The turntable failed: a frame is over the "
                                           "service's limits (too_slow)."},
    503: {"model": Problem, "headers": RETRY_AFTER,
          "description": "The turntable failed: no image within its deadline, or no worker; "
                         "POST it again to restart it."},
}


# Parsed strictly, as POST /v1/render's body ({"light_elevation": false} is refused).
BODY = {"requestBody": {"required": True, "content": {
    "application/json": {"schema": {"$ref": "#/components/schemas/TurntableRequest"}}}}}


@router.post("/v1/turntables", tags=["turntables"], status_code=202, openapi_extra=BODY,
             responses={**ERROR_RESPONSES, 404: RENDER_404, 429: BUSY},
             summary="Start a turntable: N frames around the object, then WebP, GIF or MP4")
async def turntable_post(request: Request, svc: ServiceDep, found: TurntablesDep,
                         shared: LanesDep) -> TurntableStatus:
    body = parse_body(await request.body(), TurntableRequest)
    still = prepare(body.still(), svc.context)
    check_turntable_cost(still.job, body.frames, svc.settings.cost_budget)
    frames = [still.with_job(job) for job in frame_jobs(still.job, still.preset, body.frames)]
    tasks = [(frame.key, ImageTask(frame)) for frame in frames]
    predicted = svc.pool.cost.predict(*tasks[0][1].units())
    if predicted > svc.settings.deadline_s:  # every frame would be refused: say so now
        raise TooSlow(f"each frame is predicted to take {predicted:.1f} s, over the "
                      f"{svc.settings.deadline_s:g} s limit: lower width, height, samples or "
                      "wavelengths (or choose a lower quality)")
    key = content_key({"frames": [k for k, _ in tasks], "fmt": body.animation, "fps": body.fps})
    entry = found.get(key)
    if entry is None or entry.state == "failed":
        running = sum(t.state == "running" for t in found.values())
        if running >= svc.settings.max_turntables:
            raise Busy(f"{running} turntables are rendering, the most this service runs at "
                       "once; retry later", retry_after_s=svc.settings.deadline_s)
        entry = found[key] = Turntable(key, body.frames, body.animation)
        found.move_to_end(key)
        entry.task = asyncio.create_task(run(svc, entry, tasks, body.fps, shared))
        while len(found) > KEPT:
            oldest = found.popitem(last=False)[1]
            if oldest.task is not None and oldest.state == "running":
                oldest.task.cancel()
    return entry.status()


def _entry(found: OrderedDict[str, Turntable], turntable_id: str) -> Turntable:
    entry = found.get(turntable_id)
    if entry is None:
        raise UnknownTurntable(f"turntable {turntable_id!r} is not known here: start it with "
                               "POST /v1/turntables (finished ones are forgotten after 64)")
    return entry


@router.get("/v1/turntables/{turntable_id}", tags=["turntables"],
            responses={**ERROR_RESPONSES, 404: UNKNOWN},
            summary="A turntable's progress: frames done of frames")
async def turntable_get(turntable_id: str, found: TurntablesDep) -> TurntableStatus:
    return _entry(found, turntable_id).status()


@router.get("/v1/turntables/{turntable_id}/result", tags=["turntables"],
            response_class=Response, responses=RESULT_RESPONSES,
            summary="The finished animation (409 while it renders)")
async def turntable_result(turntable_id: str, found: TurntablesDep) -> Response:
    entry = _entry(found, turntable_id)
    if entry.state == "failed" and entry.failure is not None:
        raise entry.failure  # its own public status and reason (a PublicError)
    if entry.state != "done" or entry.data is None:
        raise StillRendering(f"still rendering: {entry.done} of {entry.frames} frames done")
    headers = {"Content-Disposition": f'inline; filename="turntable{EXTENSIONS[entry.fmt]}"'}
    return Response(entry.data, media_type=MEDIA_TYPES[entry.fmt], headers=headers)
