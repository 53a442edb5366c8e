"""Turntables over HTTP: POST /v1/turntables starts one, GET says how far it is,
GET .../result answers the animation and DELETE cancels it, from any replica
(``turntable_runs`` renders them, ``turntable_jobs`` keeps them in the state store).

Each frame is an ordinary render job (cached, deduplicated, admitted, run by
the workers); a worker then encodes the frames. The cost budget covers all
frames. Progress is the count of finished frames. At most ``max_turntables`` run
at once on a replica (one more is 429 ``busy`` with Retry-After).
Failures answer in the public shape: 404 ``unknown_turntable``, 404 ``cancelled``
(after a DELETE, both reads: never a 2xx for what was deleted), 409 ``rendering``,
and a failed turntable's result answers its failure's own status (422
``too_slow``, 503 ``deadline`` ...); a state store that does not answer is 503
``store_unavailable``.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import Response

from opaline.output.animation import EXTENSIONS, MEDIA_TYPES
from opaline.server.cache import etag, matches
from opaline.server.deps import LanesDep, ServiceDep, TurntablesDep
from opaline.server.errors import (
    ERROR_RESPONSES,
    JSON_BODY_RESPONSES,
    RETRY_AFTER,
    Busy,
    Problem,
    StillRendering,
    UnknownTurntable,
)
from opaline.server.negotiation import Started, server_timing
from opaline.server.queries import json_body
from opaline.server.render_routes import CONDITIONAL, ETAG, RENDER_RESPONSES
from opaline.server.statestore import Record
from opaline.server.turntable_jobs import StoredFailure, Turntables, new_job
from opaline.server.turntable_runs import (
    TurntableStatus,
    current,
    plan,
    start,
    status_of,
    unknown_line,
)

router = APIRouter()
__all__ = ["TurntableStatus", "router"]


RENDER_404 = RENDER_RESPONSES[404]
BUSY = {"model": Problem, "headers": RETRY_AFTER,
        "description": "error 'busy': as many turntables as the service runs at once are "
                       "rendering; retry after Retry-After seconds."}
UNKNOWN_LINE = ("error 'unknown_turntable': never started here, or forgotten (the service "
                "keeps the latest 64).")
CANCELLED_LINE = " error 'cancelled': DELETE cancelled it; POST it again to start it anew."
UNKNOWN = {"model": Problem, "description": UNKNOWN_LINE}
READ_404 = {"model": Problem, "description": UNKNOWN_LINE + CANCELLED_LINE}
RESULT_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The animation: animated WebP, GIF or MP4.",
          "content": {t: {"schema": {"type": "string", "format": "binary"}}
                      for t in MEDIA_TYPES.values()}, "headers": ETAG},
    **CONDITIONAL,
    **ERROR_RESPONSES,
    404: {"model": Problem, "description": UNKNOWN_LINE + CANCELLED_LINE + " Also: its "
                                           "animation was forgotten (a byte budget keeps the "
                                           "latest); POST it again."},
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
             responses={**ERROR_RESPONSES, **JSON_BODY_RESPONSES, 404: RENDER_404, 429: BUSY},
             summary="Start a turntable: N frames around the object, then WebP, GIF or MP4")
async def turntable_post(request: Request, response: Response, svc: ServiceDep,
                         found: TurntablesDep, shared: LanesDep) -> TurntableStatus:
    raw = await json_body(request)
    planned = plan(svc, raw)
    body, _, key = planned
    record = await found.read(key)
    while record is None or await restartable(found, record):
        if len(found.running) >= svc.settings.max_turntables:
            raise Busy(f"{len(found.running)} turntables are rendering, the most this service "
                       "runs at once", retry_after_s=svc.settings.deadline_s)
        value = new_job(key, raw.decode(), body.frames, body.animation)
        record = (await start(svc, found, value, record.version if record else 0, shared,
                              planned)
                  or await found.read(key))  # or another replica started it first
    status = status_of(record.value)
    response.headers["Location"] = f"/v1/turntables/{status.id}"  # where to poll (RFC 9110)
    return status


async def restartable(found: Turntables, record: Record) -> bool:
    """Whether a POST starts the job anew: it failed, was cancelled, was orphaned, or its
    animation was forgotten (over the kept results' byte budget)."""
    state = record.value["state"]
    if state == "done":
        return await found.result(record.value["id"]) is None
    return state in ("failed", "cancelled") or found.orphaned(record)


@router.delete("/v1/turntables/{turntable_id}", tags=["turntables"], status_code=202,
               responses={**ERROR_RESPONSES, 404: UNKNOWN},
               summary="Cancel a turntable: it stops, and GET then answers 404 cancelled")
async def turntable_delete(turntable_id: str, found: TurntablesDep) -> TurntableStatus:
    record = await found.cancel(turntable_id)
    if record is None:
        raise UnknownTurntable(unknown_line(turntable_id))
    return status_of(record.value)


@router.get("/v1/turntables/{turntable_id}", tags=["turntables"],
            responses={**ERROR_RESPONSES, 404: READ_404},
            summary="A turntable's progress: frames done of frames")
async def turntable_get(turntable_id: str, svc: ServiceDep, found: TurntablesDep,
                        shared: LanesDep) -> TurntableStatus:
    return status_of(await current(svc, found, turntable_id, shared))


@router.get("/v1/turntables/{turntable_id}/result", tags=["turntables"],
            response_class=Response, responses=RESULT_RESPONSES,
            summary="The finished animation (409 while it renders)")
async def turntable_result(turntable_id: str, svc: ServiceDep, found: TurntablesDep,
                           shared: LanesDep, request: Request, started: Started) -> Response:
    entry = await current(svc, found, turntable_id, shared)
    if entry["state"] == "failed" and entry["failure"] is not None:
        raise StoredFailure(entry["failure"])  # its own public status and reason
    data = await found.result(turntable_id) if entry["state"] == "done" else None
    if data is None and entry["state"] == "done":
        raise UnknownTurntable(f"turntable {turntable_id!r}'s animation was forgotten (the "
                               "service keeps a byte budget of them): POST it again")
    if data is None:
        raise StillRendering(f"still rendering: {entry['done']} of {entry['frames']} frames "
                             "done")
    fmt = entry["fmt"]
    # As every image answer: a strong ETag (304 on a match), Cache-Control, Server-Timing.
    tag = etag(data)
    headers = {"ETag": tag, "Cache-Control": f"public, max-age={svc.settings.cache_max_age_s}"}
    if matches(request.headers.get("if-none-match"), tag):
        headers["Server-Timing"] = server_timing(started, "revalidated")
        return Response(status_code=304, headers=headers)
    headers["Content-Disposition"] = f'inline; filename="turntable{EXTENSIONS[fmt]}"'
    headers["Server-Timing"] = server_timing(started, "hit")
    return Response(data, media_type=MEDIA_TYPES[fmt], headers=headers)
