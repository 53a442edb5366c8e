"""What a worker can be asked to do: picklable descriptions, run inside the worker process.

A task's ``run(renderer, should_stop)`` returns the encoded bytes; ``units``
says what it costs for admission: (cost label, pixels × samples, wavelengths).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from opaline.model.environment_light import light_equivalents
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import Preset, all_presets
from opaline.model.request import Job, preset_fields
from opaline.output.encode import encode_mdf
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, Prepared, prepare
from opaline.pipeline.produce import produce
from opaline.scene.environments import BUILTIN, MESH_ENVIRONMENT
from opaline.workers.admission import mesh_cost_s, shading_index

StopCheck = Callable[[], bool]
MDF_LABEL = "mdf-plot"


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

    def units(self) -> tuple[str, float, int, float, float]:
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
        return self.cost_label(), units, job.wavelengths, self._mesh_s(), self.light_load()

    def light_load(self) -> float:
        """What a sample shades over its preset's own lights: 1, or an environment's light
        equivalents over them (the cost model divides it by its label calibration's)."""
        job = self.prepared.job
        if not job.environment:
            return 1.0
        return light_equivalents(job) / len(self.prepared.preset.lights)

    def _mesh_s(self) -> float:
        args = self.prepared.preset.geometry.args
        if self.prepared.preset.geometry.kind != "file":
            return 0.0
        try:
            size = os.path.getsize(args["path"])
        except OSError:
            return 0.0
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


# Calibration: a few small renders per preset, timed inside the worker, so the parent
# can predict any request's time from its pixels, samples and wavelengths.
CALIBRATION_SIZE = 192
CALIBRATION_SAMPLES = 2
CALIBRATION_WAVELENGTHS = 16
# Before it, a render is priced at the built-in guess (4× the slowest preset); the
# calibration's renders are mostly of cheaper presets: counted whole, it was predicted at
# 28.5 s where it took 7-9 s (llvmpipe, 2 cores), and a fresh server's first client was
# told to wait that long. Half (14.2 s) still waits past the time taken.
CALIBRATION_SHARE = 0.5
# Labels a calibration job times. The whole calibration (31 labels, two programs each
# compiled cold) took 33 s on OSMesa with an empty shader cache (2 cores, load 1): one job
# ran past the 30 s render limit and was killed, so the service never calibrated. Four
# labels a job took 1.7-5.2 s there.
LABELS_PER_CALIBRATION = 4
UNDER_ENVIRONMENT = "+environment"  # the label of a preset's calibration under the sky


@dataclass(frozen=True)
class CalibrateTask:
    """Time each preset at 0 and ``CALIBRATION_WAVELENGTHS`` wavelengths (after a warm-up
    render of the same variant, so compile time is not counted), and what that first render
    cost more (``cold_s``: the compile, the scene); a preset lit by its own lights also
    under the sky (label ``<name>+environment``), as light equivalents bound an
    environment's cost from above only (the sky measured 0.6-1.9× the key light where they
    counted 2-5×); answers JSON. Part ``part`` of ``parts`` times every ``parts``-th label
    from the ``part``-th (``calibration_tasks``), so that each job stays well inside the
    render time limit; the answer names its part, and the cost model merges them."""

    part: int = 0
    parts: int = 1
    label: str = "calibration"

    def labels(self) -> list[tuple[str, Preset, str | None]]:
        return calibrated_labels()[self.part::self.parts]

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        timings: dict[str, list[float]] = {}
        cold: dict[str, float] = {}
        loads: dict[str, float] = {}
        for label, preset, environment in self.labels():
            tasks = [ImageTask(prepare(self._request(preset, w, environment), PRIVATE))
                     for w in (0, CALIBRATION_WAVELENGTHS)]
            both = [self._time_task(renderer, task, should_stop) for task in tasks]
            timings[label] = [warm for _, warm in both]
            cold[label] = max(first - warm for first, warm in both)
            loads[label] = min(task.light_load() for task in tasks)
        tiny = RenderRequest(width=16, height=16, samples=1, wavelengths=0, quality="draft")
        overhead = self._time_task(renderer, ImageTask(prepare(tiny, PRIVATE)), should_stop)[1]
        units = CALIBRATION_SIZE * CALIBRATION_SIZE * CALIBRATION_SAMPLES
        return json.dumps({"part": self.part, "parts": self.parts,
                           "overhead_s": overhead, "units": units,
                           "wavelengths": CALIBRATION_WAVELENGTHS, "timings": timings,
                           "cold_s": cold, "light_load": loads}).encode()

    @staticmethod
    def _request(preset: Preset, wavelengths: int, environment: str | None = None
                 ) -> RenderRequest:
        return RenderRequest(preset=preset.name, width=CALIBRATION_SIZE,
                             height=CALIBRATION_SIZE, samples=CALIBRATION_SAMPLES,
                             wavelengths=wavelengths, environment=environment)

    @staticmethod
    def _time_task(renderer: Any, task: ImageTask, should_stop: StopCheck
                   ) -> tuple[float, float]:
        """Seconds of the variant's first render (its compile, its scene) and of the next."""
        seconds = []
        for _ in range(2):
            start = time.perf_counter()
            task.run(renderer, should_stop)
            seconds.append(time.perf_counter() - start)
        return seconds[0], seconds[1]

    def units(self) -> tuple[str, float, int]:
        """Four renders per label (a warm-up and a timing at each of two wavelength
        counts), half of them spectral: so admission counts the work ahead of a request."""
        per_render = CALIBRATION_SIZE * CALIBRATION_SIZE * CALIBRATION_SAMPLES
        return ("calibration", CALIBRATION_SHARE * 4.0 * len(self.labels()) * per_render,
                CALIBRATION_WAVELENGTHS // 2)


def calibration_tasks() -> list[CalibrateTask]:
    """The start-up calibration as jobs of at most ``LABELS_PER_CALIBRATION`` labels each."""
    parts = -(-len(calibrated_labels()) // LABELS_PER_CALIBRATION)
    return [CalibrateTask(part, parts) for part in range(parts)]


def lit_by_own_lights(preset: Preset) -> bool:
    """A preset whose defaults name no environment: calibrated under the sky as well."""
    return not preset.defaults.environment


def calibrated_labels() -> list[tuple[str, Preset, str | None]]:
    """(label, preset, environment) of every calibration: each preset as it is, and each
    preset lit by its own lights also under the sky."""
    labels: list[tuple[str, Preset, str | None]] = []
    for name, preset in all_presets().items():
        labels.append((name, preset, None))
        if lit_by_own_lights(preset):
            labels.append((name + UNDER_ENVIRONMENT, preset, MESH_ENVIRONMENT))
    return labels
