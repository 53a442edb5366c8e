"""The Python API: a request in, encoded bytes or an array out, no HTTP involved.

    from opaline.local import pipeline
    with pipeline.LocalRenderer() as r:
        png = r.render_bytes(RenderRequest(preset="cd-rom", mu_f=6))

One LocalRenderer owns one GL context; use it from the thread that made it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from opaline.gl.renderer import Renderer
from opaline.local.context import local_context
from opaline.model.params import Material, RenderRequest
from opaline.model.request import Job, check_plot_cost
from opaline.output.encode import encode_mdf
from opaline.pipeline.prepare import Prepared, prepare
from opaline.pipeline.produce import produce
from opaline.settings import setting


@dataclass
class Rendered:
    job: Job
    data: bytes
    media_type: str


def budget_of(cost_budget: int | None) -> int:
    """A local render's cost budget: as given, else OPALINE_COST_BUDGET (as the service's)."""
    return setting("cost_budget") if cost_budget is None else cost_budget


def prepare_locally(request: RenderRequest, cost_budget: int | None = None) -> Prepared:
    """A request prepared in this process (checked against the limits and the budget): no
    GL, so a refusal costs no context."""
    return prepare(request, local_context(budget_of(cost_budget)))


class LocalRenderer:
    """Renders requests on a private headless context."""

    def __init__(self, backend: str | None = None, cost_budget: int | None = None) -> None:
        self.renderer = Renderer(backend, environments_dir=setting("environments_dir"),
                                 environment_paths=True)
        self.cost_budget = cost_budget  # None: OPALINE_COST_BUDGET, as in the HTTP service

    @property
    def budget(self) -> int:
        return budget_of(self.cost_budget)

    def __enter__(self) -> LocalRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.renderer.release()

    def prepare(self, request: RenderRequest) -> Prepared:
        return prepare_locally(request, self.cost_budget)

    def produce(self, prepared: Prepared) -> bytes:
        return produce(prepared, self.renderer)

    def job(self, request: RenderRequest) -> Job:
        return self.prepare(request).job

    def render_bytes(self, request: RenderRequest) -> bytes:
        return self.produce(self.prepare(request))

    def render_array(self, request: RenderRequest) -> np.ndarray:
        """Linear, premultiplied RGBA float32 (H, W, 4)."""
        prepared = self.prepare(request)
        job = replace(prepared.job, format="npy")
        linear = self.renderer.render(job, prepared.preset).linear
        assert linear is not None  # an npy job always reads back linear radiance
        return linear

    def mdf_plot(self, material: Material, size: int, wavelengths: int = 0) -> np.ndarray:
        check_plot_cost(size, wavelengths, self.budget)
        return self.renderer.mdf_plot(material, size, wavelengths)

    def mdf_bytes(
        self, material: Material, size: int, fmt: str = "png", wavelengths: int = 0
    ) -> bytes:
        return encode_mdf(self.mdf_plot(material, size, wavelengths), fmt)
