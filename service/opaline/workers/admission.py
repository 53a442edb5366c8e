"""Predicting a render's time, so that work that cannot meet its deadline is refused at once.

The model per cost label (a preset, or the MDF plot) is

    seconds = overhead + per_unit · pixels·samples · (1 + per_wavelength · wavelengths)

fitted from ``CalibrateTask``'s timings, measured in a worker at start-up.
Until those arrive, and for labels the calibration did not cover, the slowest
calibrated label (or a conservative built-in guess) stands in, and every
prediction carries a safety factor: refusing a job that would have made it is
cheaper than letting it hold a worker past its deadline.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Sequence
from dataclasses import dataclass, field

from opaline.workers.errors import Overloaded, TooSlow, Unavailable

# Before calibration: about 4× the slowest preset measured on a 2-core llvmpipe machine
# (oil-slick, 256² draft: 25 ms for 65,536 pixel-samples), and 5% more per wavelength.
DEFAULT_PER_UNIT_S = 1.5e-6
DEFAULT_PER_WAVELENGTH = 0.05
DEFAULT_OVERHEAD_S = 0.02
SAFETY = 1.5
# A mesh check (workers.mesh_tasks) is priced by its file's size: trimesh's import on a
# worker's first check, then about 0.14 s/MB for the slowest format (ASCII PLY), and at
# most its own time limit, after which the worker is killed.
CHECK_LABEL = "mesh-check"
CHECK_TIME_LIMIT_S = 5.0
CHECK_BASE_S = 1.0
CHECK_S_PER_BYTE = 0.15 / (1 << 20)


@dataclass
class Coefficients:
    per_unit_s: float
    per_wavelength: float


@dataclass
class CostModel:
    overhead_s: float = DEFAULT_OVERHEAD_S
    labels: dict[str, Coefficients] = field(default_factory=dict)
    calibrated: bool = False
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def predict(self, label: str, units: float, wavelengths: int) -> float:
        """Predicted seconds for a task (safety factor included)."""
        if label == CHECK_LABEL:
            return check_cost_s(units)
        with self._lock:
            found = self.labels.get(label) or self._slowest()
        raw = self.overhead_s + found.per_unit_s * units * (1.0 + found.per_wavelength * wavelengths)
        return SAFETY * raw

    def _slowest(self) -> Coefficients:
        if not self.labels:
            return Coefficients(DEFAULT_PER_UNIT_S, DEFAULT_PER_WAVELENGTH)
        return Coefficients(max(c.per_unit_s for c in self.labels.values()),
                            max(c.per_wavelength for c in self.labels.values()))

    def calibrate(self, report: bytes) -> None:
        """Fit the coefficients from ``CalibrateTask``'s JSON answer."""
        data = json.loads(report)
        overhead = max(0.0, float(data["overhead_s"]))
        units, wavelengths = float(data["units"]), float(data["wavelengths"])
        labels = {}
        for label, (plain, spectral) in data["timings"].items():
            # The fixed cost is measured on a tiny image; keep at least a fifth of each
            # timing as per-pixel work, so that noise cannot make a preset look free.
            per_unit = max(plain - overhead, 0.2 * plain) / units
            extra = max(spectral - overhead, 0.2 * spectral) / (per_unit * units) - 1.0
            labels[label] = Coefficients(per_unit, max(extra, 0.0) / wavelengths)
        with self._lock:
            self.overhead_s, self.labels, self.calibrated = overhead, labels, True

    def describe(self) -> dict[str, object]:
        with self._lock:
            return {"calibrated": self.calibrated, "overhead_s": round(self.overhead_s, 5),
                    "labels": {k: {"per_unit_s": c.per_unit_s, "per_wavelength": c.per_wavelength}
                               for k, c in self.labels.items()}}


def check_cost_s(size_bytes: float) -> float:
    """Predicted seconds of a mesh check of a ``size_bytes`` file, up to its time limit."""
    return min(CHECK_TIME_LIMIT_S, SAFETY * (CHECK_BASE_S + CHECK_S_PER_BYTE * size_bytes))


def admit(predicted: float, workers: int, running: Sequence[float], queued: Sequence[float],
          queue_size: int, deadline_s: float) -> Exception | None:
    """Why a job predicted to take ``predicted`` seconds cannot be taken now, or None.

    ``running``: the predicted seconds left of each job being rendered; ``queued``:
    the predictions of the jobs waiting. The work ahead is shared by the workers."""
    if not workers:
        return Unavailable("no render worker has a GL context (the server log says why)")
    if predicted > deadline_s:
        return TooSlow(f"this request is predicted to take {predicted:.1f} s, over the "
                       f"{deadline_s:g} s limit: lower width, height, samples or wavelengths "
                       "(or choose a lower quality)")
    backlog = (sum(running) + sum(queued)) / workers
    if len(queued) >= queue_size or backlog + predicted > deadline_s:
        return Overloaded(f"{len(queued)} jobs are waiting, about {backlog:.1f} s of work",
                          retry_after_s=max(1.0, backlog))
    return None
