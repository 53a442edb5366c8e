"""Routes that answer with an image: render (GET and POST) and the MDF plot.

Each parses its input into the models of ``opaline.model.params``, resolves
it to a ``Job``, answers from the cache or through the worker pool, and
leaves every failure to ``opaline.server.errors``. While a render is awaited
the route also listens for the client leaving: the last client to leave
withdraws the job (dropped from the queue, or stopped between samples).
"""

from __future__ import annotations

import time
from typing import Annotated, Any

from fastapi import APIRouter, Depends, HTTPException, Query, Request
from fastapi.responses import Response

from opaline.model.params import MATERIAL_FIELDS, Material, RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import Job, check_cost, check_plot_cost, resolve
from opaline.output.encode import EXTENSIONS, MEDIA_TYPES
from opaline.output.formats import HAS_ALPHA, negotiate
from opaline.server.cache import etag, matches, mdf_key
from opaline.server.errors import ERROR_RESPONSES, LimitError, Problem
from opaline.server.queries import MdfQuery, RenderQuery
from opaline.server.service import Service, get_service
from opaline.settings import Settings
from opaline.workers.tasks import ImageTask, MdfTask, Task

ServiceDep = Annotated[Service, Depends(get_service)]


def clock() -> float:
    """When the route began (dependencies run before the query is parsed): the start of
    the server's own time in the Server-Timing header."""
    return time.perf_counter()


Started = Annotated[float, Depends(clock)]


def _over_limit(name: str, value: int, limit: int) -> str:
    return f"{name}={value} is out of range: allowed [16 … {limit}] on this service"


def check_limits(job: Job, settings: Settings) -> None:
    problems = [_over_limit(name, value, limit)
                for name, value, limit in (("width", job.width, settings.max_width),
                                           ("height", job.height, settings.max_height))
                if value > limit]
    if problems:
        raise LimitError(problems)
    check_cost(job, settings.cost_budget)


def check_mdf_limits(params: MdfQuery, settings: Settings) -> None:
    size = min(settings.max_width, settings.max_height)
    if params.size > size:
        raise LimitError([_over_limit("size", params.size, size)])
    check_plot_cost(params.size, params.wavelengths, settings.cost_budget)


def client_gone(request: Request):
    """An awaitable that resolves when the client disconnects (the body is already read)."""
    async def wait() -> None:
        while (await request.receive())["type"] != "http.disconnect":
            pass
    return wait


def server_timing(started: float, source: str, render_s: float | None = None) -> str:
    """``total``: the route's own time; ``render``: waiting for the worker, on a miss."""
    parts = [f'{source};desc="{source}"']
    if render_s is not None:
        parts.append(f"render;dur={1e3 * render_s:.2f}")
    parts.append(f"total;dur={1e3 * (time.perf_counter() - started):.2f}")
    return ", ".join(parts)


async def answer_image(svc: Service, request: Request, key: str, task: Task, fmt: str,
                       filename: str, started: float, vary: bool = False) -> Response:
    """The image under ``key``: 304, from the cache, or rendered by a worker."""
    tag = etag(key, svc.pool.identity)
    headers = {"ETag": tag}
    if vary:
        headers["Vary"] = "Accept"
    if request.method == "GET":
        headers["Cache-Control"] = f"public, max-age={svc.settings.cache_max_age_s}"
        if matches(request.headers.get("if-none-match"), tag):
            headers["Server-Timing"] = server_timing(started, "revalidated")
            return Response(status_code=304, headers=headers)
    data = svc.cache.get(key)
    render_s = None
    if data is not None:
        svc.metrics.cache_hits.inc()
    else:
        svc.metrics.cache_misses.inc()
        begun = time.perf_counter()
        data = await svc.pool.render(key, task, timeout=svc.wait_s, gone=client_gone(request))
        render_s = time.perf_counter() - begun
    headers["Content-Disposition"] = f'inline; filename="{filename}{EXTENSIONS[fmt]}"'
    headers["Server-Timing"] = server_timing(started, "hit" if render_s is None else "miss",
                                             render_s)
    return Response(data, media_type=MEDIA_TYPES[fmt], headers=headers)


def negotiated(params: RenderRequest, request: Request) -> RenderRequest:
    """``format=auto`` replaced by the format the Accept header prefers (406 if none)."""
    fmt = negotiate(request.headers.get("accept"), alpha=bool(params.transparent))
    if fmt is None:
        raise HTTPException(406, "format=auto: the Accept header allows none of image/webp, "
                            "image/avif, image/png, image/jpeg")
    return params.model_copy(update={"format": fmt})


async def answer_render(svc: Service, request: Request, params: RenderRequest,
                        started: float) -> Response:
    auto = params.format == "auto"
    if auto:
        params = negotiated(params, request)
    preset = get_preset(params.preset)
    job = resolve(params, preset)
    if job.transparent and job.format not in HAS_ALPHA:
        raise LimitError([f"format={job.format} has no alpha channel: transparent=true needs "
                          "png, png16, webp, webp-lossless or avif"])
    check_limits(job, svc.settings)
    key = job.cache_key(preset.scene_key())
    return await answer_image(svc, request, key, ImageTask(job, preset), job.format, preset.name,
                              started, vary=auto)


IMAGE = {"schema": {"type": "string", "format": "binary"}}
ETAG = {"ETag": {"description": "Strong validator of this image as this service draws it; "
                                "a GET that sends it back in If-None-Match gets 304.",
                 "schema": {"type": "string"}}}
CONDITIONAL: dict[int | str, dict[str, Any]] = {
    304: {"description": "Not modified: If-None-Match matched the ETag."}}
RENDER_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The image: PNG (8- or 16-bit sRGB), WebP, AVIF, JPEG or .npy (linear "
                         "float32 RGBA); format=auto picks from Accept and sends Vary: Accept.",
          "content": {t: IMAGE for t in ("image/png", "image/webp", "image/avif", "image/jpeg",
                                         "application/x-npy")}, "headers": ETAG},
    406: {"model": Problem, "description": "format=auto and Accept allows no image type made."},
    404: {"model": Problem, "description": "Unknown preset; the message lists the valid ones."},
    413: {"model": Problem, "description": "Request body too large."},
    **ERROR_RESPONSES,
}
MDF_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The MDF plot: PNG (normalised, sRGB) or .npy (linear D, float32).",
          "content": {"image/png": IMAGE, "application/x-npy": IMAGE}, "headers": ETAG},
    **CONDITIONAL, **ERROR_RESPONSES,
}
router = APIRouter()


@router.post("/v1/render", tags=["render"], response_class=Response, responses=RENDER_RESPONSES,
             summary="Render a preset with material overrides (JSON body)")
async def render_post(started: Started, body: RenderRequest, request: Request,
                      svc: ServiceDep) -> Response:
    return await answer_render(svc, request, body, started)


@router.get("/v1/render", tags=["render"], response_class=Response,
            responses={**RENDER_RESPONSES, **CONDITIONAL},
            summary="Render a preset with material overrides (query string, for <img src>)")
async def render_get(started: Started, params: Annotated[RenderQuery, Query()],
                     request: Request, svc: ServiceDep) -> Response:
    return await answer_render(svc, request, params, started)


@router.get("/v1/mdf", tags=["render"], response_class=Response, responses=MDF_RESPONSES,
            summary="Plot the MDF over the projected half-vector disc (Figs. 2, 3, 6, 7)")
async def mdf_get(started: Started, params: Annotated[MdfQuery, Query()], request: Request,
                  svc: ServiceDep) -> Response:
    check_mdf_limits(params, svc.settings)
    material = Material(**params.model_dump(include=set(MATERIAL_FIELDS), exclude_none=True))
    key = mdf_key(material, params.size, params.format, params.wavelengths)
    task = MdfTask(material, params.size, params.format, params.wavelengths)
    return await answer_image(svc, request, key, task, params.format, "mdf", started)
