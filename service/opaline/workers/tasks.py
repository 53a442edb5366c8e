"""What a worker can be asked to do: picklable descriptions, run inside the worker process.

A task's ``run(renderer, should_stop)`` returns the encoded bytes; ``units``
says what it costs for admission: (cost label, pixels × samples, wavelengths).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from opaline.model.environment_light import light_equivalents
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import Preset
from opaline.model.request import Job, preset_fields
from opaline.output.encode import encode_mdf
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, Prepared
from opaline.pipeline.produce import produce
from opaline.scene.environments import BUILTIN
from opaline.workers.admission import (
    CHECK_ADVICE,
    MDF_LABEL,
    RENDER_ADVICE,
    mesh_cost_s,
    shading_index,
)

StopCheck = Callable[[], bool]
# The fields a request sets that drive a render's time, as a refusal names them.
COST_FIELDS = ("environment_samples", "environment_lights", "samples", "wavelengths", "width",
               "height", "grating_orders", "film_stack_pairs")


def no_meshes(request: RenderRequest, preset: Preset) -> Preset:
    raise AssertionError("the worker's own renders draw presets only")


# The worker's own renders (calibration, warm-up): built-in presets, no budget.
PRIVATE = Context(Limits(cost_budget=None), no_meshes)


class Task(Protocol):
    # Read-only, so a frozen dataclass's field or a property both satisfy it.
    @property
    def label(self) -> str: ...

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes: ...

    # (cost label, pixels × samples, wavelengths[, seconds of its own])
    def units(self) -> tuple[Any, ...]: ...


@dataclass(frozen=True)
class ImageTask:
    """Render a prepared job and encode it in the job's format (``pipeline.produce``)."""

    prepared: Prepared

    @property
    def job(self) -> Job:
        return self.prepared.job

    @property
    def label(self) -> str:
        """The preset the request names, a user's mesh or not (the metrics' label)."""
        return self.prepared.named.name

    def cost_label(self) -> str:
        """The calibrated label the job is priced by: the named preset's, or the same preset
        timed under an environment where the job has one and the preset's own lights were
        timed (a user's mesh is lit by the sky unless told otherwise)."""
        if self.prepared.job.environment and lit_by_own_lights(self.prepared.named):
            return self.label + UNDER_ENVIRONMENT
        return self.label

    def cold_label(self) -> str | None:
        """The label whose first render at calibration (its compile, its scene) stands for
        this variant's; None where the job loads a map no calibration did (a file's)."""
        job, own = self.prepared.job, self.prepared.named.defaults.environment
        if job.environment in (None, own) or job.environment in BUILTIN:
            return self.cost_label()
        return None

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        return produce(self.prepared, renderer, should_stop)

    def variant(self) -> tuple[object, ...]:
        """What selects the program a worker compiles and the scene it builds: the job's
        categorical fields. Admission prices a variant no worker has rendered yet with its
        compile (``CostModel.predict_task``); a define a numeric field switches is missed."""
        job = self.prepared.job
        material = tuple(sorted((k, v) for k, v in job.material.model_dump().items()
                                if isinstance(v, (str, bool))
                                or k in ("grating_orders", "film_stack_pairs")))
        material += (("coat", job.material.coat_weight > 0.0),)  # COAT's define
        return (self.prepared.preset.name, self.prepared.preset.geometry.args.get("path"),
                job.wavelengths, job.samples, job.aa, job.tonemap, job.color_space,
                job.transparent,
                job.environment, job.environment_lights, job.environment_samples,
                job.environment_background, material)

    def units(self) -> tuple[str, float, int, float, float, float]:
        job, preset = self.prepared.job, self.prepared.preset
        units = float(job.width * job.height * job.samples)
        # Calibrated on the preset's own material: a costlier source or more orders scale
        # it up (never down: the calibration is the floor).
        own = preset_fields(preset)
        material = job.material
        units *= max(1.0, shading_index(material.iridescence, material.grating_orders,
                                        material.film_stack_pairs, material.coat_weight > 0.0)
                     / shading_index(own.get("iridescence") or "rotation",
                                     own.get("grating_orders") or 3,
                                     own.get("film_stack_pairs") or 0,
                                     (own.get("coat_weight") or 0.0) > 0.0))
        read_s, draw_s = self._mesh_s()
        return self.cost_label(), units, job.wavelengths, draw_s, self.light_load(), read_s

    def light_load(self) -> float:
        """What a sample shades over its preset's own lights: 1, or an environment's light
        equivalents over them (the cost model divides it by its label calibration's)."""
        job = self.prepared.job
        if not job.environment:
            return 1.0
        return light_equivalents(job) / len(self.prepared.preset.lights)

    def advice(self, predicted: float) -> tuple[str, list[str]]:
        """What a refusal as too slow (``predicted`` seconds) advises, and the request fields
        it names: those of the cost's drivers the request set (their values), and the mesh
        file where it is half the time or more (a 2M-triangle scan's refusal named only
        width and height, which could not help)."""
        request = self.prepared.request
        named = [name for name in COST_FIELDS if name in request.model_fields_set]
        lower = ", ".join(f"{name}={getattr(request, name)}" for name in named)
        advice = (f"lower {lower} (or width, height, samples, wavelengths, or the quality)"
                  if named else RENDER_ADVICE)
        read_s, draw_s = self._mesh_s()
        if read_s + draw_s >= 0.5 * predicted:
            advice = (f"its mesh file alone takes about {read_s + draw_s:.1f} s: {CHECK_ADVICE};"
                      f" or {advice}")
            named.append("mesh")
        return advice, named

    @property
    def read_s(self) -> float:
        """Seconds of the mesh file's read that ``units`` counts (admission's pace)."""
        return self._mesh_s()[0]

    def _mesh_s(self) -> tuple[float, float]:
        """Seconds the request's mesh file costs a render: its read, and its drawing."""
        args = self.prepared.preset.geometry.args
        if self.prepared.preset.geometry.kind != "file":
            return 0.0, 0.0
        try:
            size = os.path.getsize(args["path"])
        except OSError:
            return 0.0, 0.0
        passes = self.job.samples if self.job.wavelengths or self.job.samples % 4 else max(
            1, self.job.samples // 4)
        return mesh_cost_s(size, int(args.get("max_triangles", 2_000_000)), passes)


@dataclass(frozen=True)
class MdfTask:
    """Plot the MDF: normalised sRGB PNG or linear npy."""

    material: Material
    size: int
    fmt: str
    wavelengths: int
    label: str = MDF_LABEL

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        return encode_mdf(renderer.mdf_plot(self.material, self.size, self.wavelengths), self.fmt)

    def units(self) -> tuple[str, float, int]:
        return MDF_LABEL, float(self.size * self.size), self.wavelengths


UNDER_ENVIRONMENT = "+environment"  # the label of a preset's calibration under the sky


def lit_by_own_lights(preset: Preset) -> bool:
    """A preset whose defaults name no environment: calibrated under the sky as well."""
    return not preset.defaults.environment
