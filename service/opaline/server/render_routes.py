"""Routes that answer with an image: render (GET and POST) and the MDF plot.

Each parses its input into the models of ``opaline.model.params``, resolves
it to a ``Job``, answers from the cache or through the worker pool, and
leaves every failure to ``opaline.server.errors``. While a render is awaited
the route also listens for the client leaving: the last client to leave
withdraws the job (dropped from the queue, or stopped between samples).
"""

from __future__ import annotations

import time
from collections.abc import Awaitable, Callable
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Request
from fastapi.responses import Response

from opaline.model.auto import auto_headers
from opaline.model.params import RenderRequest
from opaline.model.request import check_plot_cost
from opaline.output.encode import EXTENSIONS, MEDIA_TYPES
from opaline.pipeline.limits import LimitError, over_limit
from opaline.pipeline.prepare import prepare
from opaline.server.cache import etag, matches, mdf_key
from opaline.server.canonical import (
    IMMUTABLE,
    CanonicalMdfQuery,
    CanonicalQuery,
    canonical_plot,
    is_canonical,
    mdf_url,
    plot_material,
)
from opaline.server.deps import ServiceDep
from opaline.server.errors import ERROR_RESPONSES, JSON_BODY_RESPONSES, Problem
from opaline.server.negotiation import Started, negotiated, server_timing
from opaline.server.queries import MdfQuery, json_body, parse_body
from opaline.server.query_params import documented, query_model
from opaline.server.service import Service
from opaline.server.streaming import image_response
from opaline.settings import Settings
from opaline.workers.tasks import ImageTask, MdfTask, Task


def check_mdf_limits(params: MdfQuery, settings: Settings) -> None:
    size = min(settings.max_width, settings.max_height)
    if params.size > size:
        raise LimitError([over_limit("size", params.size, size)], ["size"])
    check_plot_cost(params.size, params.wavelengths, settings.cost_budget)


def client_gone(request: Request) -> Callable[[], Awaitable[None]]:
    """An awaitable that resolves when the client disconnects (the body is already read)."""
    async def wait() -> None:
        while (await request.receive())["type"] != "http.disconnect":
            pass
    return wait


async def answer_image(svc: Service, request: Request, key: str, task: Task, fmt: str,
                       filename: str, started: float, headers: dict[str, str] | None = None,
                       vary: bool = False) -> Response:
    """The image under ``key``: 304, from the cache, or rendered by a worker."""
    headers = dict(headers or {})
    if vary:
        headers["Vary"] = "Accept"
    if request.method == "GET":
        headers.setdefault("Cache-Control", f"public, max-age={svc.settings.cache_max_age_s}")
        tag = svc.cache.tag(key)
        if tag is not None and matches(request.headers.get("if-none-match"), tag):
            headers["Server-Timing"] = server_timing(started, "revalidated")
            return Response(status_code=304, headers={**headers, "ETag": tag})
    data = svc.cache.get(key)
    render_s = None
    if data is not None:
        svc.metrics.cache_hits.inc()
    else:
        svc.metrics.cache_misses.inc()
        begun = time.perf_counter()
        data = await svc.pool.render(key, task, timeout=svc.wait_s, gone=client_gone(request))
        render_s = time.perf_counter() - begun
    headers["ETag"] = svc.cache.tag(key) or etag(data)
    headers["Content-Disposition"] = f'inline; filename="{filename}{EXTENSIONS[fmt]}"'
    headers["Server-Timing"] = server_timing(started, "hit" if render_s is None else "miss",
                                             render_s)
    return image_response(data, MEDIA_TYPES[fmt], headers)


async def answer_render(svc: Service, request: Request, params: RenderRequest,
                        started: float) -> Response:
    """Every answer names the image's canonical GET URL in Content-Location; only that URL
    is immutable (another spelling, or a stale rev, may lead elsewhere after an upgrade).
    ``format=auto`` is negotiated from Accept first; the answer then varies by Accept."""
    auto = params.format == "auto"
    if auto:
        params = negotiated(params, request)
    prepared = prepare(params, svc.context)
    job, url = prepared.job, prepared.url()
    headers = {"Content-Location": url, **auto_headers(job)}  # what quality=auto picked
    if request.method == "GET" and is_canonical(request.url.query, url):
        headers["Cache-Control"] = IMMUTABLE
    return await answer_image(svc, request, prepared.key, ImageTask(prepared), job.format,
                              prepared.preset.name, started, headers, vary=auto)


IMAGE = {"schema": {"type": "string", "format": "binary"}}
ETAG = {"ETag": {"description": "Strong validator: a hash of the image's bytes, the same from "
                                "every replica that draws them; a GET that sends it back in "
                                "If-None-Match gets 304.",
                 "schema": {"type": "string"}}}
LOCATION = {"Content-Location": {"description": "The image's canonical GET URL: parameters in "
                                                "a fixed order, defaults dropped, rev = its "
                                                "content key; immutable, one URL per image.",
                                 "schema": {"type": "string"}}}
CONDITIONAL: dict[int | str, dict[str, Any]] = {
    304: {"description": "Not modified: If-None-Match matched the ETag."}}
RENDER_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The image: PNG (8- or 16-bit sRGB), WebP, AVIF, JPEG or .npy (linear "
                         "float32 RGBA); format=auto picks from Accept and sends Vary: Accept.",
          "content": {t: IMAGE for t in ("image/png", "image/webp", "image/avif", "image/jpeg",
                                         "application/x-npy")}, "headers": {**ETAG, **LOCATION}},
    406: {"model": Problem, "description": "format=auto and Accept allows no image type made."},
    413: {"model": Problem, "description": "Request body too large."},
    **ERROR_RESPONSES,
    404: {"model": Problem, "description": "error 'unknown_preset' (the message lists the valid "
                                           "ones), 'unknown_mesh' or 'unknown_environment' (not "
                                           "built in, not a file of the environments folder)."},
}
MDF_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The MDF plot: PNG (normalised, sRGB) or .npy (linear D, float32).",
          "content": {"image/png": IMAGE, "application/x-npy": IMAGE},
          "headers": {**ETAG, **LOCATION}},
    **CONDITIONAL, **ERROR_RESPONSES,
}
router = APIRouter()


# The body is parsed strictly by parse_body (numbers are JSON numbers), so the route
# documents it itself instead of letting FastAPI parse it laxly.
BODY = {"requestBody": {"required": True, "content": {
    "application/json": {"schema": {"$ref": "#/components/schemas/RenderRequest"}}}}}


@router.post("/v1/render", tags=["render"], response_class=Response,
             responses={**RENDER_RESPONSES, **JSON_BODY_RESPONSES},
             summary="Render a preset with material overrides (JSON body)", openapi_extra=BODY)
async def render_post(started: Started, request: Request, svc: ServiceDep) -> Response:
    return await answer_render(svc, request, parse_body(await json_body(request), RenderRequest),
                               started)


# The query strings are read by query_model (FastAPI's own reading of a Query() model cost
# 0.2 ms a request); documented() lists their parameters as FastAPI would.
@router.get("/v1/render", tags=["render"], response_class=Response,
            responses={**RENDER_RESPONSES, **CONDITIONAL}, openapi_extra=documented(CanonicalQuery),
            summary="Render a preset with material overrides (query string, for <img src>)")
async def render_get(started: Started,
                     params: Annotated[CanonicalQuery, Depends(query_model(CanonicalQuery))],
                     request: Request, svc: ServiceDep) -> Response:
    return await answer_render(svc, request, params.request(), started)


@router.get("/v1/mdf", tags=["render"], response_class=Response, responses=MDF_RESPONSES,
            openapi_extra=documented(CanonicalMdfQuery),
            summary="Plot the MDF over the projected half-vector disc (Figs. 2, 3, 6, 7)")
async def mdf_get(started: Started,
                  query: Annotated[CanonicalMdfQuery, Depends(query_model(CanonicalMdfQuery))],
                  request: Request, svc: ServiceDep) -> Response:
    params, canonical = canonical_plot(query.plot())
    check_mdf_limits(params, svc.settings)
    material = plot_material(params)
    key = mdf_key(material, params.size, params.format, params.wavelengths)
    url = mdf_url(canonical, key)
    headers = {"Content-Location": url}
    if is_canonical(request.url.query, url):
        headers["Cache-Control"] = IMMUTABLE
    task = MdfTask(material, params.size, params.format, params.wavelengths)
    return await answer_image(svc, request, key, task, params.format, "mdf", started, headers)
