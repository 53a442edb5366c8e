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
from opaline.model.meshes import file_mesh_preset
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import Preset, get_preset
from opaline.model.request import Job, check_cost, check_plot_cost, resolve
from opaline.output.encode import encode_frame, encode_mdf
from opaline.settings import setting


@dataclass
class Rendered:
    job: Job
    data: bytes
    media_type: str


class LocalRenderer:
    """Renders requests on a private headless context."""

    def __init__(self, backend: str | None = None, cost_budget: int | None = None) -> None:
        self.renderer = Renderer(backend, environments_dir=setting("environments_dir"))
        self.cost_budget = cost_budget  # None: OPALINE_COST_BUDGET, as in the HTTP service

    @property
    def budget(self) -> int:
        return setting("cost_budget") if self.cost_budget is None else self.cost_budget

    def __enter__(self) -> LocalRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.renderer.release()

    @property
    def mesh_presets(self) -> dict[str, Preset]:
        """Presets made for mesh files: jobs name their preset, and these are in no folder
        (made on first use, so subclasses that skip ``__init__`` still have one)."""
        return self.__dict__.setdefault("_mesh_presets", {})

    def preset(self, request: RenderRequest) -> Preset:
        """The request's preset, drawing the request's mesh file if it names one."""
        preset = get_preset(request.preset)
        if request.mesh is None:
            return preset
        preset = file_mesh_preset(preset, request, setting("mesh_max_triangles"))
        self.mesh_presets[preset.name] = preset
        return preset

    def job(self, request: RenderRequest) -> Job:
        job = resolve(request, self.preset(request))
        check_cost(job, self.budget)
        return job

    def render_job(self, job: Job) -> bytes:
        frame = self.renderer.render(job, self.mesh_presets.get(job.preset))
        return encode_frame(frame, job.format, alpha=job.transparent)

    def render_bytes(self, request: RenderRequest) -> bytes:
        return self.render_job(self.job(request))

    def render_array(self, request: RenderRequest) -> np.ndarray:
        """Linear, premultiplied RGBA float32 (H, W, 4)."""
        job = replace(self.job(request), format="npy")
        linear = self.renderer.render(job, self.mesh_presets.get(job.preset)).linear
        assert linear is not None  # an npy job always reads back linear radiance
        return linear

    def mdf_plot(self, material: Material, size: int, wavelengths: int = 0) -> np.ndarray:
        check_plot_cost(size, wavelengths, self.budget)
        return self.renderer.mdf_plot(material, size, wavelengths)

    def mdf_bytes(
        self, material: Material, size: int, fmt: str = "png", wavelengths: int = 0
    ) -> bytes:
        return encode_mdf(self.mdf_plot(material, size, wavelengths), fmt)
