"""What the routes depend on: the settings, the worker pool, the image cache, the metrics."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from fastapi import Depends, Request

from opaline.server.cache import ImageCache
from opaline.server.metrics import Metrics
from opaline.settings import Settings, get_settings
from opaline.workers.pool import WorkerPool

SettingsDep = Annotated[Settings, Depends(get_settings)]


@dataclass
class Service:
    settings: Settings
    pool: WorkerPool
    cache: ImageCache
    metrics: Metrics

    @property
    def wait_s(self) -> float:
        """How long a request waits for its image: queued until the deadline, then the render
        until the watchdog (which answers first, with 503, if the render hangs)."""
        return self.settings.deadline_s + self.settings.render_timeout_s + 1.0


def get_service(request: Request, settings: SettingsDep) -> Service:
    state = request.app.state
    return Service(settings, state.pool, state.cache, state.metrics)
