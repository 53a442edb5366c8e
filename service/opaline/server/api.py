"""The HTTP service: the app factory, its lifespan, and the operational routes.

    uvicorn --factory opaline.server.api:create_app      (or: opaline serve)

Image routes live in ``render_routes``; failures get their public face in
``errors``. The HTTP process never touches GL: renders run in the worker
processes of ``opaline.workers``, so the event loop answers within
milliseconds whatever a render does.
"""

from __future__ import annotations

import asyncio
import os
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from functools import partial
from pathlib import Path
from typing import Any

from fastapi import APIRouter, FastAPI
from fastapi.responses import FileResponse, RedirectResponse, Response
from pydantic import BaseModel

from opaline import __version__, scratch
from opaline.model.camera import key_light_direction
from opaline.model.params import RenderRequest
from opaline.model.presets import Preset, all_presets, get_preset
from opaline.model.request import resolve
from opaline.model.tiers import TIERS
from opaline.model.turntable import TurntableRequest
from opaline.pipeline.prepare import prepare
from opaline.server.access import Access
from opaline.server.body_limit import BodyLimit
from opaline.server.cache import ImageCache
from opaline.server.check_lane import check_lane
from opaline.server.connections import STATS as CONNECTION_STATS
from opaline.server.deps import ServiceDep, SettingsDep
from opaline.server.docs import SecurityHeaders, mount_docs
from opaline.server.errors import ERROR_RESPONSES, Problem, install
from opaline.server.export_routes import router as export_router
from opaline.server.mesh_routes import router as mesh_router
from opaline.server.meshstore import MeshStore
from opaline.server.methods import Methods
from opaline.server.metrics import Metrics
from opaline.server.render_routes import router as render_router
from opaline.server.schemas import Health, PresetInfo, Readiness, TierInfo
from opaline.server.statestore import LocalState, StateStore
from opaline.server.turntable_jobs import Turntables
from opaline.server.turntable_routes import router as turntable_router
from opaline.settings import Settings, get_settings, memory_budget_bytes
from opaline.workers.calibration import calibration_tasks
from opaline.workers.factory import RendererFactory
from opaline.workers.pool import WorkerPool
from opaline.workers.tasks import PRIVATE, ImageTask

WEB_DIR = Path(__file__).resolve().parent / "web"
router = APIRouter()

__all__ = ["SettingsDep", "WEB_DIR", "create_app", "mount_web"]


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


@router.get("/v1/tiers", tags=["presets"],
            summary="The quality tiers: samples, wavelengths, AA and environment lights of each")
async def tiers_list() -> list[TierInfo]:
    return [TierInfo.model_validate(tier.describe()) for tier in TIERS.values()]


@router.get("/v1/presets/{name}", tags=["presets"], summary="One preset with its defaults",
            responses={404: {"model": Problem, "description": "Unknown preset."}})
async def presets_one(name: str) -> PresetInfo:
    return preset_info(get_preset(name))


@router.get("/healthz", tags=["operations"], summary="Liveness: the process answers",
            description="200 while the HTTP process and its event loop answer, whatever the "
                        "render workers do: a liveness probe (restart the container if it "
                        "fails). Whether the service can render is /readyz.")
async def healthz() -> Health:
    return Health(status="ok")


@router.get("/readyz", tags=["operations"], summary="Readiness: a worker can render",
            description="200 while at least one render worker process has a working GL "
                        "context and the start-up warm-up and calibration are done, else 503 "
                        "(during those seconds admission would refuse renders): a readiness "
                        "probe and the container's health check. Lists every worker with its "
                        "pid, state, renders, memory, restarts and last error.",
            responses={503: {"model": Readiness, "description": "No worker can render."}})
async def readyz(svc: ServiceDep, response: Response) -> Readiness:
    workers = svc.pool.status()
    ready = next((w for w in workers if w["state"] in ("ready", "busy")), None)
    response.status_code = 200 if svc.pool.ready else 503
    return Readiness(ready=svc.pool.ready, backend=(ready or {}).get("backend"),
                     renderer=(ready or {}).get("renderer"), queue_depth=svc.pool.depth(),
                     calibrated=svc.pool.cost.calibrated,
                     memory_budget_bytes=memory_budget_bytes(svc.settings), workers=workers,
                     checks=svc.checks.status())


@router.get("/metrics", tags=["operations"], summary="Prometheus metrics",
            response_class=Response,
            responses={200: {"content": {Metrics.content_type: {"schema": {"type": "string"}}}}})
async def metrics_get(svc: ServiceDep) -> Response:
    return Response(svc.metrics.exposition(), media_type=Metrics.content_type)


def warmup_task() -> ImageTask:
    """Compile the default preset's shaders before the first request."""
    return ImageTask(prepare(RenderRequest(width=16, height=16, quality="draft"), PRIVATE))


def mount_web(app: FastAPI, web_dir: Path = WEB_DIR) -> None:
    """The web page at '/' when the web folder has one; otherwise '/' leads to the docs."""
    from fastapi.staticfiles import StaticFiles

    index = web_dir / "index.html"
    if index.is_file():
        app.mount("/static", StaticFiles(directory=web_dir), name="static")
        app.add_api_route("/", lambda: FileResponse(index), include_in_schema=False)
    else:
        app.add_api_route("/", lambda: RedirectResponse("/docs"), include_in_schema=False)


@asynccontextmanager
async def lifespan(app: FastAPI) -> AsyncIterator[None]:
    all_presets()  # an invalid preset stops the start-up, naming the file and field
    scratch.sweep(*scratch.WORKER_KINDS)  # a killed run's (its mesh folder: the store's)
    await asyncio.gather(*(asyncio.to_thread(p.start) for p in (app.state.pool, app.state.checks)))
    try:
        yield
    finally:
        await app.state.turntables.stop()  # before the workers: stopped, not failed
        await asyncio.gather(*(asyncio.to_thread(p.stop) for p in (app.state.pool,
                                                                   app.state.checks)))
        # Here, not at exit: uvicorn re-raises SIGTERM/SIGINT, so atexit never runs.
        app.state.meshes.close()
        scratch.sweep(*scratch.WORKER_KINDS)  # every worker gone: what a killed one left


def renderer_for(settings: Settings) -> RendererFactory:
    """The recipe each worker process follows to make its renderer."""
    mib = 1024 * 1024
    return RendererFactory(settings.gl_backend, max_programs=settings.worker_programs,
                           scene_bytes=settings.worker_scene_mb * mib,
                           target_bytes=settings.worker_target_mb * mib,
                           environments_dir=settings.environments_dir)


def open_state(settings: Settings) -> StateStore:
    """The store ``settings.state_url`` names: this process's memory when unset."""
    if settings.state_url is None:
        return LocalState(settings.mesh_store_bytes, settings.turntable_result_bytes)
    from opaline.server.redisstate import RedisState  # the redis package only when used

    return RedisState(settings.state_url, settings.mesh_store_bytes,
                      timeout_s=settings.state_timeout_s)


def document(app: FastAPI, *models: type[BaseModel]) -> None:
    """Put ``models`` among the OpenAPI components: routes that parse their own body
    refer to them (and the web page reads RenderRequest from there)."""
    generate = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is not None:
            return app.openapi_schema
        schema = generate()  # FastAPI's keeps it as app.openapi_schema too
        schemas = schema.setdefault("components", {}).setdefault("schemas", {})
        for model in models:
            schemas[model.__name__] = model.model_json_schema(
                ref_template="#/components/schemas/{model}")
        return schema

    # Replacing the method is FastAPI's documented way to extend the schema (its docs,
    # "Extending OpenAPI"); its type declares a method, so mypy sees a method overwritten.
    app.openapi = openapi  # type: ignore[method-assign]


def create_app(settings: Settings | None = None, renderer_factory: Any = None) -> FastAPI:
    """The service; its lifespan starts the render workers and stops them at shutdown.

    ``renderer_factory`` (called in each worker process, so it must be picklable:
    a module-level function or a partial of one) defaults to a ``Renderer`` on
    ``settings.gl_backend``; tests pass one that fails on purpose.
    """
    if settings is None:
        settings = get_settings()
    metrics = Metrics()
    cache = ImageCache(settings.cache_bytes)
    lp_threads = settings.lp_threads or max(1, (os.cpu_count() or 1) // settings.workers)
    pool = WorkerPool(
        renderer_factory or renderer_for(settings), workers=settings.workers,
        queue_size=settings.queue_size, deadline_s=settings.deadline_s,
        render_timeout_s=settings.render_timeout_s, max_renders=settings.worker_max_renders,
        max_rss_bytes=settings.worker_max_rss_mb * 1024 * 1024, lp_threads=lp_threads,
        cache=cache, on_rendered=lambda label, s: metrics.render_seconds.labels(label).observe(s),
        startup=[*([warmup_task()] if settings.warmup else []),
                 *(calibration_tasks() if settings.calibrate else [])])
    metrics.watch(pool.depth, lambda: cache.size_bytes)
    metrics.watch_pool(pool.counters, lambda: cache.evictions)
    metrics.watch_connections(CONNECTION_STATS)
    app = FastAPI(title="Opaline", version=__version__, lifespan=lifespan,
                  docs_url=None, redoc_url=None, redirect_slashes=False,
                  responses={k: ERROR_RESPONSES[k] for k in (403, 404, 422, 429, 500)},
                  description="Headless previews of iridescent materials "
                              "(Kang, Lee, Cho 2014, multi-peak anisotropic microfacet model).")
    app.state.settings, app.state.pool = settings, pool
    app.state.cache, app.state.metrics = cache, metrics
    state = open_state(settings)
    app.state.meshes = MeshStore(settings, state)
    app.state.checks = check_lane(settings)
    app.state.turntables = Turntables(state, settings)
    app.state.turntable_lanes = asyncio.Semaphore(settings.workers)
    app.add_middleware(BodyLimit, limit=settings.max_body_bytes,
                       on_reject=partial(metrics.reject, "too_large"),
                       paths={"/v1/meshes": settings.mesh_max_bytes})
    install(app)
    app.add_middleware(Methods, routes_of=app, on_reject=metrics.reject)
    app.add_middleware(Access, settings=settings, on_reject=metrics.reject)
    app.add_middleware(SecurityHeaders)
    app.include_router(render_router)
    app.include_router(mesh_router)
    app.include_router(turntable_router)
    app.include_router(export_router)
    app.include_router(router)
    document(app, RenderRequest, TurntableRequest)
    mount_docs(app)
    mount_web(app)
    return app
