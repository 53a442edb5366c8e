"""What the routes work with: the settings, the worker pool, the image cache, the metrics,
the mesh store and the mesh-check lane (``deps.get_service`` hands it to each route)."""

from __future__ import annotations

from dataclasses import dataclass

from opaline.model.params import RenderRequest
from opaline.model.presets import Preset
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context
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
    checks: WorkerPool  # the mesh-check lane (``check_lane``)

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
