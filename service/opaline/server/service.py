"""What the routes work with: the settings, the worker pool, the image cache, the metrics
and the mesh store (``deps.get_service`` hands it to each route)."""

from __future__ import annotations

from dataclasses import dataclass

from opaline.server.cache import ImageCache
from opaline.server.meshstore import MeshStore
from opaline.server.metrics import Metrics
from opaline.settings import Settings
from opaline.workers.pool import WorkerPool


@dataclass
class Service:
    settings: Settings
    pool: WorkerPool
    cache: ImageCache
    metrics: Metrics
    meshes: MeshStore

    @property
    def wait_s(self) -> float:
        """How long a request waits for its image: queued until the deadline, then the render
        until the watchdog (which answers first, with 503, if the render hangs)."""
        return self.settings.deadline_s + self.settings.render_timeout_s + 1.0
