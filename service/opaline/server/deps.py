"""What the routes depend on, as FastAPI dependencies: the one place that reads the app's
state (``create_app`` puts it there), so no route reaches into ``request.app.state``.

Every dependency here is async: FastAPI runs a plain ``def`` one in its thread pool, a
hand-off there and back (0.2-0.3 ms of a cache miss on two busy cores).
"""

from __future__ import annotations

import asyncio
import inspect
from typing import Annotated

from fastapi import Depends, Request

from opaline.server.service import Service
from opaline.server.turntable_jobs import Turntables
from opaline.settings import Settings, get_settings


async def app_settings(request: Request) -> Settings:
    """The app's settings (``create_app``'s), or what a test put in place of ``get_settings``
    in ``app.dependency_overrides`` (called with no arguments: such an override may not
    take dependencies of its own).

    Read here rather than through an override that ``create_app`` registers: while any
    override is registered, FastAPI rebuilds every dependency of every request from its
    signature (0.1 ms of each cache miss, docs/speed.md, "The path around the render")."""
    override = request.app.dependency_overrides.get(get_settings)
    if override is None:
        settings: Settings = getattr(request.app.state, "settings", None) or get_settings()
        return settings
    settings = override()
    return await settings if inspect.isawaitable(settings) else settings


async def get_service(request: Request) -> Service:
    """The routes' view of the app."""
    state = request.app.state
    return Service(await app_settings(request), state.pool, state.cache, state.metrics,
                   state.meshes, state.checks)


async def turntables(request: Request) -> Turntables:
    """The turntable jobs: in the state store, and those this replica runs."""
    known: Turntables = request.app.state.turntables
    return known


async def turntable_lanes(request: Request) -> asyncio.Semaphore:
    """The frame lanes every turntable shares: one per worker."""
    lanes: asyncio.Semaphore = request.app.state.turntable_lanes
    return lanes


SettingsDep = Annotated[Settings, Depends(app_settings)]
ServiceDep = Annotated[Service, Depends(get_service)]
TurntablesDep = Annotated[Turntables, Depends(turntables)]
LanesDep = Annotated[asyncio.Semaphore, Depends(turntable_lanes)]
