"""What the routes depend on: the settings, the worker pool, the image cache, the metrics."""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Annotated

from fastapi import Depends, Request

from opaline.model.params import RenderRequest
from opaline.model.presets import Preset
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context
from opaline.server.cache import ImageCache
from opaline.server.meshstore import MeshStore
from opaline.server.metrics import Metrics
from opaline.settings import Settings, get_settings
from opaline.workers.pool import WorkerPool


@dataclass
class Service:
    settings: Settings
    pool: WorkerPool
    cache: ImageCache
    metrics: Metrics
    meshes: MeshStore

    @property
    def context(self) -> Context:
        """Requests are prepared against this service's limits, its uploaded meshes and its
        environments folder."""
        s = self.settings
        return Context(Limits(s.cost_budget, s.max_width, s.max_height), self.mesh_preset,
                       s.environments_dir)

    def mesh_preset(self, request: RenderRequest, preset: Preset) -> Preset:
        return self.meshes.preset(request, preset, self.settings.mesh_max_triangles)

    @property
    def wait_s(self) -> float:
        """How long a request waits for its image: queued until the deadline, then the render
        until the watchdog (which answers first, with 503, if the render hangs)."""
        return self.settings.deadline_s + self.settings.render_timeout_s + 1.0


async def app_settings(request: Request) -> Settings:
    """The app's settings (``create_app``'s), or what a test put in place of ``get_settings``
    in ``app.dependency_overrides`` (called with no arguments: such an override may not
    take dependencies of its own).

    Read here rather than through an override that ``create_app`` registers: while any
    override is registered, FastAPI rebuilds every dependency of every request from its
    signature (0.1 ms of each cache miss, docs/speed.md, "The path around the render")."""
    override = request.app.dependency_overrides.get(get_settings)
    if override is None:
        return getattr(request.app.state, "settings", None) or get_settings()
    settings = override()
    return await settings if inspect.isawaitable(settings) else settings


SettingsDep = Annotated[Settings, Depends(app_settings)]


async def get_service(request: Request) -> Service:
    """The routes' view of the app. Async, as every dependency on the image path: FastAPI
    runs a plain ``def`` one in its thread pool, a hand-off there and back (0.2-0.3 ms of a
    cache miss on two busy cores)."""
    state = request.app.state
    return Service(await app_settings(request), state.pool, state.cache, state.metrics,
                   state.meshes)
