"""The HTTP API: thin routes over request → cache → render workers → response.

    uvicorn --factory service.api:create_app      (or: opaline serve)

Each route parses its input into the models of ``service.params``, resolves
it to a ``Job`` (``service.request``), answers from the cache or through the
worker pool (``service.worker``), and leaves every failure to the handlers
of ``service.errors``, which give each a public face: 422 with one line per
problem, 404 for an unknown preset, 413, 503 with Retry-After, 500 with an
incident id (the traceback goes only to the server log).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from contextlib import asynccontextmanager
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Annotated, Any

from fastapi import APIRouter, Depends, FastAPI, Query, Request
from fastapi.responses import FileResponse, RedirectResponse, Response
from fastapi.staticfiles import StaticFiles
from pydantic import BaseModel, Field

from opaline import __version__
from opaline.gl.camera import key_light_direction
from opaline.gl.renderer import Renderer
from opaline.model.params import MATERIAL_FIELDS, Material, RenderRequest
from opaline.model.presets import Preset, all_presets, get_preset
from opaline.model.request import TIERS, Job, check_cost, check_plot_cost, resolve
from opaline.model.spectrum import rgb_weights
from opaline.output.encode import EXTENSIONS, MEDIA_TYPES
from opaline.server.cache import ImageCache, etag, matches, mdf_key
from opaline.server.errors import ERROR_RESPONSES, LimitError, Problem, install
from opaline.server.metrics import Metrics
from opaline.server.queries import MdfQuery, RenderQuery
from opaline.server.worker import Task, WorkerPool, image_task, mdf_task
from opaline.settings import Settings, get_settings

WEB_DIR = Path(__file__).resolve().parent / "web"
MDF_LABEL = "mdf-plot"  # the render-latency label of MDF plots

SettingsDep = Annotated[Settings, Depends(get_settings)]


class PresetInfo(BaseModel):
    """A preset as the API shows it."""

    name: str
    description: str
    figure: str
    geometry: dict[str, Any] = Field(description="Geometry generator and its arguments.")
    tangents: str
    normal_map: dict[str, Any] | None
    defaults: dict[str, Any] = Field(description="The fields the preset sets itself.")
    resolved: dict[str, Any] = Field(
        description="What a request naming only this preset renders: every value resolved.")
    key_light: dict[str, float] | None = Field(
        None, description="Where the preset puts its key light, in degrees, as light_azimuth "
        "and light_elevation measure them.")


class Readiness(BaseModel):
    """What /readyz answers, with 200 or 503 alike."""

    ready: bool
    backend: str | None = Field(description="GL backend of the first ready worker.")
    renderer: str | None = Field(description="GL renderer string of the first ready worker.")
    queue_depth: int = Field(description="Jobs waiting for a render worker.")
    workers: list[dict[str, Any]] = Field(
        description="Each worker: name, state, restarts, its GL context's description, and "
        "the last error when it has no context.")


# Services the routes depend on


@dataclass
class Service:
    settings: Settings
    pool: WorkerPool
    cache: ImageCache
    metrics: Metrics

    @property
    def wait_s(self) -> float:
        return self.settings.deadline_s + self.settings.render_timeout_s


def get_service(request: Request, settings: SettingsDep) -> Service:
    state = request.app.state
    return Service(settings, state.pool, state.cache, state.metrics)


ServiceDep = Annotated[Service, Depends(get_service)]


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


async def answer_image(svc: Service, request: Request, key: str, task: Task, label: str,
                       fmt: str, filename: str) -> Response:
    """The image under ``key``: 304, from the cache, or rendered by a worker."""
    tag = etag(key, svc.pool.identity)
    headers = {"ETag": tag}
    if request.method == "GET":
        headers["Cache-Control"] = f"public, max-age={svc.settings.cache_max_age_s}"
        if matches(request.headers.get("if-none-match"), tag):
            return Response(status_code=304, headers=headers)
    data = svc.cache.get(key)
    if data is not None:
        svc.metrics.cache_hits.inc()
    else:
        svc.metrics.cache_misses.inc()
        data = await svc.pool.render(key, task, label, timeout=svc.wait_s)
    headers["Content-Disposition"] = f'inline; filename="{filename}{EXTENSIONS[fmt]}"'
    return Response(data, media_type=MEDIA_TYPES[fmt], headers=headers)


async def answer_render(svc: Service, request: Request, params: RenderRequest) -> Response:
    preset = get_preset(params.preset)
    job = resolve(params, preset)
    check_limits(job, svc.settings)
    key = job.cache_key(preset.scene_key())
    return await answer_image(svc, request, key, image_task(job, preset), preset.name,
                              job.format, preset.name)


# Routes

IMAGE = {"schema": {"type": "string", "format": "binary"}}
ETAG = {"ETag": {"description": "Strong validator of this image as this service draws it; "
                                "a GET that sends it back in If-None-Match gets 304.",
                 "schema": {"type": "string"}}}
CONDITIONAL: dict[int | str, dict[str, Any]] = {
    304: {"description": "Not modified: If-None-Match matched the ETag."}}
RENDER_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {"description": "The image: PNG (8- or 16-bit sRGB) or .npy (linear float32 RGBA).",
          "content": {"image/png": IMAGE, "application/x-npy": IMAGE}, "headers": ETAG},
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
async def render_post(body: RenderRequest, request: Request, svc: ServiceDep) -> Response:
    return await answer_render(svc, request, body)


@router.get("/v1/render", tags=["render"], response_class=Response,
            responses={**RENDER_RESPONSES, **CONDITIONAL},
            summary="Render a preset with material overrides (query string, for <img src>)")
async def render_get(params: Annotated[RenderQuery, Query()], request: Request,
                     svc: ServiceDep) -> Response:
    return await answer_render(svc, request, params)


@router.get("/v1/mdf", tags=["render"], response_class=Response, responses=MDF_RESPONSES,
            summary="Plot the MDF over the projected half-vector disc (Figs. 2, 3, 6, 7)")
async def mdf_get(params: Annotated[MdfQuery, Query()], request: Request,
                  svc: ServiceDep) -> Response:
    check_mdf_limits(params, svc.settings)
    material = Material(**params.model_dump(include=set(MATERIAL_FIELDS), exclude_none=True))
    key = mdf_key(material, params.size, params.format, params.wavelengths)
    task = mdf_task(material, params.size, params.format, params.wavelengths)
    return await answer_image(svc, request, key, task, MDF_LABEL, params.format, "mdf")


def preset_info(preset: Preset) -> PresetInfo:
    data = preset.model_dump(mode="json")
    return PresetInfo(
        name=preset.name, description=preset.description, figure=preset.figure,
        geometry=data["geometry"], tangents=preset.tangents, normal_map=data["normal_map"],
        defaults=preset.defaults.model_dump(mode="json", exclude_none=True),
        resolved=resolve(RenderRequest(preset=preset.name), preset).canonical(),
        key_light=_rounded(key_light_direction(preset.lights, preset.camera.target)),
    )


def _rounded(direction: dict[str, float] | None) -> dict[str, float] | None:
    return None if direction is None else {k: round(v, 1) for k, v in direction.items()}


@router.get("/v1/presets", tags=["presets"], summary="Every preset with its defaults")
async def presets_list() -> list[PresetInfo]:
    return [preset_info(p) for p in all_presets().values()]


@router.get("/v1/presets/{name}", tags=["presets"], summary="One preset with its defaults",
            responses={404: {"model": Problem, "description": "Unknown preset."}})
async def presets_one(name: str) -> PresetInfo:
    return preset_info(get_preset(name))


@router.get("/healthz", tags=["operations"], summary="The process is alive")
async def healthz() -> dict[str, str]:
    return {"status": "ok"}


@router.get("/readyz", tags=["operations"], summary="A render worker has a live GL context",
            responses={503: {"model": Readiness, "description": "No worker has a GL context."}})
async def readyz(svc: ServiceDep, response: Response) -> Readiness:
    workers = svc.pool.status()
    ready = next((w for w in workers if w["state"] == "ready"), None)
    response.status_code = 200 if ready else 503
    return Readiness(ready=ready is not None, backend=(ready or {}).get("backend"),
                     renderer=(ready or {}).get("renderer"), queue_depth=svc.pool.depth(),
                     workers=workers)


@router.get("/metrics", tags=["operations"], summary="Prometheus metrics",
            response_class=Response,
            responses={200: {"content": {Metrics.content_type: {"schema": {"type": "string"}}}}})
async def metrics_get(svc: ServiceDep) -> Response:
    return Response(svc.metrics.exposition(), media_type=Metrics.content_type)


# The app


def warmup_task() -> Task:
    """Compile the default preset's shaders and load the CIE tables before the first request."""
    job = resolve(RenderRequest(width=16, height=16, quality="draft"))
    draw = image_task(job, get_preset(job.preset))

    def run(renderer: Any) -> bytes:
        rgb_weights(int(TIERS["high"]["wavelengths"]))
        return draw(renderer)

    return run


def mount_web(app: FastAPI, web_dir: Path = WEB_DIR) -> None:
    """The web page at '/' when service/web/ has one; otherwise '/' leads to the docs."""
    index = web_dir / "index.html"
    if index.is_file():
        app.mount("/static", StaticFiles(directory=web_dir), name="static")
        app.add_api_route("/", lambda: FileResponse(index), include_in_schema=False)
    else:
        app.add_api_route("/", lambda: RedirectResponse("/docs"), include_in_schema=False)


@asynccontextmanager
async def lifespan(app: FastAPI):
    all_presets()  # an invalid preset stops the start-up, naming the file and field
    await asyncio.to_thread(app.state.pool.start)
    try:
        yield
    finally:
        await asyncio.to_thread(app.state.pool.stop)


def create_app(settings: Settings | None = None,
               renderer_factory: Callable[[], Any] | None = None) -> FastAPI:
    """The service; its lifespan starts the render workers and stops them at shutdown.

    ``renderer_factory`` (called on each worker thread) defaults to a ``Renderer``
    on ``settings.gl_backend``; tests pass one that fails on purpose.
    """
    if settings is None:
        settings = get_settings()
    metrics = Metrics()
    cache = ImageCache(settings.cache_bytes)
    factory = renderer_factory or partial(Renderer, settings.gl_backend)
    pool = WorkerPool(factory, workers=settings.workers,
                      queue_size=settings.queue_size, deadline_s=settings.deadline_s,
                      cache=cache, metrics=metrics,
                      warmup=warmup_task() if settings.warmup else None)
    metrics.watch(pool.depth, lambda: cache.size_bytes)
    app = FastAPI(title="Opaline", version=__version__, lifespan=lifespan,
                  description="Headless previews of iridescent materials "
                              "(Kang, Lee, Cho 2014, multi-peak anisotropic microfacet model).")
    app.state.settings, app.state.pool = settings, pool
    app.state.cache, app.state.metrics = cache, metrics
    app.dependency_overrides[get_settings] = lambda: settings
    install(app, settings.max_body_bytes, metrics)
    app.include_router(router)
    mount_web(app)
    return app
