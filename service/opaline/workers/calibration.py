"""The start-up calibration: a few small renders per preset, timed inside a worker, so
that the parent can predict any request's time from its pixels, samples and wavelengths
(``workers/admission.CostModel``), as jobs of a few labels each."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from typing import Any

from opaline.model.params import Material, RenderRequest
from opaline.model.presets import Preset, all_presets
from opaline.pipeline.prepare import prepare
from opaline.scene.environments import MESH_ENVIRONMENT
from opaline.workers.admission import MDF_LABEL
from opaline.workers.tasks import (
    PRIVATE,
    UNDER_ENVIRONMENT,
    ImageTask,
    MdfTask,
    StopCheck,
    lit_by_own_lights,
)

CALIBRATION_SIZE = 192
CALIBRATION_SAMPLES = 2
CALIBRATION_WAVELENGTHS = 16
MDF_CALIBRATION_SIZE = 256  # the MDF plot's, timed with the first part
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
        if self.part == 0:
            timings[MDF_LABEL] = self._time_plots(renderer, should_stop, units)
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

    def _time_plots(self, renderer: Any, should_stop: StopCheck, units: int) -> list[float]:
        """The MDF plot's seconds at 0 and the calibration's wavelengths, the dearer of the
        two MDFs, scaled to ``units`` pixels (a plot has no samples). Unpriced, a plot was
        priced as the slowest preset: a 384² plot was refused as 21.5 s, and took 0.05."""
        side = MDF_CALIBRATION_SIZE
        found = []
        for wavelengths in (0, CALIBRATION_WAVELENGTHS):
            found.append(max(self._time_task(renderer, MdfTask(Material(mdf=mdf), side, "png",
                                                               wavelengths), should_stop)[1]
                             for mdf in ("ashikhmin", "multipeak")) * units / side ** 2)
        return found

    @staticmethod
    def _time_task(renderer: Any, task: ImageTask | MdfTask, should_stop: StopCheck
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


def calibrated_labels() -> list[tuple[str, Preset, str | None]]:
    """(label, preset, environment) of every calibration: each preset as it is, and each
    preset lit by its own lights also under the sky."""
    labels: list[tuple[str, Preset, str | None]] = []
    for name, preset in all_presets().items():
        labels.append((name, preset, None))
        if lit_by_own_lights(preset):
            labels.append((name + UNDER_ENVIRONMENT, preset, MESH_ENVIRONMENT))
    return labels
