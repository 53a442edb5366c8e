"""What a worker can be asked to do: picklable descriptions, run inside the worker process.

A task's ``run(renderer, should_stop)`` returns the encoded bytes; ``units``
says what it costs for admission: (cost label, pixels × samples, wavelengths).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from opaline.gl.lighting import environment_count
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import Preset, all_presets
from opaline.model.request import Job, resolve
from opaline.output.encode import encode_frame, encode_mdf

StopCheck = Callable[[], bool]
MDF_LABEL = "mdf-plot"


class Task(Protocol):
    label: str

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes: ...

    def units(self) -> tuple[str, float, int]: ...


@dataclass(frozen=True)
class ImageTask:
    """Render a resolved job and encode it in the job's format."""

    job: Job
    preset: Preset

    @property
    def label(self) -> str:
        return self.preset.name

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        frame = renderer.render(self.job, self.preset, should_stop=should_stop)
        return encode_frame(frame, self.job.format, alpha=self.job.transparent)

    def units(self) -> tuple[str, float, int]:
        job = self.job
        units = float(job.width * job.height * job.samples)
        if job.environment:  # calibrated on the preset's lights; the cost grows with K
            units *= max(1.0, environment_count(job) / len(self.preset.lights))
        return self.preset.name, units, job.wavelengths


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


@dataclass(frozen=True)
class CalibrateTask:
    """Time each preset at 0 and ``CALIBRATION_WAVELENGTHS`` wavelengths (after a warm-up
    render of the same variant, so compile time is not counted); answers JSON."""

    label: str = "calibration"

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        timings: dict[str, list[float]] = {}
        for name, preset in all_presets().items():
            timings[name] = [self._time(renderer, preset, w, should_stop)
                             for w in (0, CALIBRATION_WAVELENGTHS)]
        tiny = resolve(RenderRequest(width=16, height=16, samples=1, wavelengths=0,
                                     quality="draft"))
        overhead = self._time_job(renderer, tiny, all_presets()[tiny.preset], should_stop)
        units = CALIBRATION_SIZE * CALIBRATION_SIZE * CALIBRATION_SAMPLES
        return json.dumps({"overhead_s": overhead, "units": units,
                           "wavelengths": CALIBRATION_WAVELENGTHS, "timings": timings}).encode()

    def _time(self, renderer: Any, preset: Preset, wavelengths: int, should_stop: StopCheck
              ) -> float:
        job = resolve(RenderRequest(preset=preset.name, width=CALIBRATION_SIZE,
                                    height=CALIBRATION_SIZE, samples=CALIBRATION_SAMPLES,
                                    wavelengths=wavelengths), preset)
        return self._time_job(renderer, job, preset, should_stop)

    @staticmethod
    def _time_job(renderer: Any, job: Job, preset: Preset, should_stop: StopCheck) -> float:
        task = ImageTask(job, preset)
        task.run(renderer, should_stop)  # compiles the variant
        start = time.perf_counter()
        task.run(renderer, should_stop)
        return time.perf_counter() - start

    def units(self) -> tuple[str, float, int]:
        """Four renders per preset (a warm-up and a timing at each of two wavelength
        counts), half of them spectral: so admission counts the work ahead of a request."""
        per_render = CALIBRATION_SIZE * CALIBRATION_SIZE * CALIBRATION_SAMPLES
        return ("calibration", 4.0 * len(all_presets()) * per_render,
                CALIBRATION_WAVELENGTHS // 2)
