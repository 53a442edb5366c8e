"""Predicting a render's time, so that work that cannot meet its deadline is refused at once.

The model per cost label (a preset, or the MDF plot) is

    seconds = overhead + extra + per_unit · units · (1 + per_wavelength · W · growth(W))

fitted from ``CalibrateTask``'s timings, measured in a worker at start-up. ``units``
is pixels × samples, times the material's shading cost over its preset's own
(``shading_index``: a grating's orders); ``growth`` is how much a wavelength
costs more past the calibrated 16 (measured on llvmpipe: 1.0-1.8× at 128);
``extra`` is a task's own seconds (a mesh file's parse and its triangles). ``units``
grow with what a sample shades (an environment's light equivalents over the preset's
lights) past what its label's calibration shaded.
A user's mesh is priced by the preset its request names (its material and lights); a
job under an environment on a preset lit by its own lights, by that preset's timing
under the sky (``ImageTask.cost_label``).
A task whose variant (``ImageTask.variant``: its program and scene) no worker has
rendered yet also pays ``cold``, its label's first render over its second at
calibration: the program's compile and the scene's build (0.01-0.04 s on llvmpipe,
up to 0.9 s where an environment map is loaded; more than a small image's render),
or the slowest label's where the job reads a map from a file. Mesa's shader cache on
disk makes a compile it holds nearly free (the sphere under the studio, A-S MDF, 512²: a
first render in 0.07 s with its program there, 0.41-0.45 s without): a server started
with the calibration's programs in that cache and a request's not undercounts that
request's compile. A new container from the Dockerfile starts with the cache empty, so
its calibration measures real compiles; a restarted one keeps the cache in its home.
Until those arrive, and for labels the calibration did not cover, the slowest
calibrated label (or a conservative built-in guess) stands in, and every
prediction carries a safety factor: refusing a job that would have made it is
cheaper than letting it hold a worker past its deadline.
"""

from __future__ import annotations

import json
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import Any

from opaline.workers.errors import Overloaded, TooSlow, Unavailable
from opaline.workers.pace import Pace

# Before calibration: about 4× the slowest preset measured on a 2-core llvmpipe machine
# (oil-slick, 256² draft: 25 ms for 65,536 pixel-samples), and 5% more per wavelength.
DEFAULT_PER_UNIT_S = 1.5e-6
DEFAULT_PER_WAVELENGTH = 0.05
DEFAULT_OVERHEAD_S = 0.02
# A variant's first render over its second at calibration (192², llvmpipe): 0.01-0.04 s
# for most presets, 0.13-0.93 s where the preset loads an environment map. Before the
# calibration, a typical compile: more would refuse every new variant under a short deadline.
DEFAULT_COLD_S = 0.1
SAFETY = 1.5
WARM_VARIANTS = 64  # as many as a worker keeps compiled by default (worker_programs)
# A mesh check (workers.mesh_tasks) is priced by its file's size: trimesh's import on a
# worker's first check, then about 0.14 s/MB for the slowest format (ASCII PLY), and at
# most its own time limit, after which the worker is killed.
CHECK_LABEL = "mesh-check"
MDF_LABEL = "mdf-plot"  # the MDF plot's label (workers/tasks.MdfTask)
CHECK_TIME_LIMIT_S = 10.0  # 64 MiB, the largest upload, parses in about 8.5 s
CHECK_BASE_S = 1.0
CHECK_S_PER_BYTE = 0.15 / (1 << 20)
# Per triangle and pass: 1.3M triangles drew in 0.25 s a pass (llvmpipe, 256²); a file
# holds at least 12 bytes a triangle (uint32 indices of shared vertices).
TRIANGLE_PASS_S = 0.25e-6
MIN_BYTES_PER_TRIANGLE = 12
COAT_COST = 1.3  # shading_index
GROWTH_W = 208.0  # growth(W) = (1 + W/208) / (1 + W_calibrated/208): ×1.5 at 128 from 16


@dataclass
class Coefficients:
    per_unit_s: float
    per_wavelength: float


@dataclass
class CostModel:
    overhead_s: float = DEFAULT_OVERHEAD_S
    calibration_wavelengths: int = 16
    labels: dict[str, Coefficients] = field(default_factory=dict)
    cold: dict[str, float] = field(default_factory=dict)
    # What each label's calibration shaded a sample (``ImageTask.light_load``): a preset lit
    # by an environment was timed with it, which a job's own must not add again.
    light_load: dict[str, float] = field(default_factory=dict)
    calibrated: bool = False
    _parts: set[int] = field(default_factory=set, repr=False)  # the calibration's, in
    _warm: OrderedDict[Hashable, None] = field(default_factory=OrderedDict, repr=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    pace: Pace = field(default_factory=Pace)  # the load since the calibration (workers.pace)

    def predict_task(self, task: Any) -> float:
        """``predict`` of the task's units, and its variant's first-render cost if no
        worker has rendered that variant lately."""
        units = task.units()
        variant = getattr(task, "variant", None)
        if variant is None:
            return self.predict(*units)
        key = variant()  # outside the lock: it reads the whole material
        label = task.cold_label()
        with self._lock:
            cold = key not in self._warm
            slowest = self._slowest_cold()
            cold_s = slowest if label is None else self.cold.get(label, slowest)
        return self.predict(*units) + (SAFETY * cold_s if cold else 0.0)

    def warmed(self, task: Any) -> None:
        """A worker rendered ``task``: its variant is compiled (the newest few are kept)."""
        variant = getattr(task, "variant", None)
        if variant is None:
            return
        key = variant()
        with self._lock:
            self._warm[key] = None
            self._warm.move_to_end(key)
            while len(self._warm) > WARM_VARIANTS:
                self._warm.popitem(last=False)

    def predict(self, label: str, units: float, wavelengths: int, extra_s: float = 0.0,
                light_load: float = 1.0, read_s: float = 0.0) -> float:
        """Predicted seconds for a task (safety factor included); ``light_load``: what a
        sample shades over its preset's lights, scaling the units past the calibration's;
        ``read_s``: a mesh file's read, at the slowest format's rate already, so without
        the safety factor (with it, a 2M-triangle scan was refused at every size)."""
        if label == CHECK_LABEL:
            return check_cost_s(units)
        with self._lock:
            found = self.labels.get(label) or self._slowest()
            units *= max(1.0, light_load / self.light_load.get(label, 1.0))
        growth = (1.0 + wavelengths / GROWTH_W) / (1.0 + self.calibration_wavelengths / GROWTH_W)
        spectral = found.per_wavelength * wavelengths * growth
        estimate = self.overhead_s + extra_s + found.per_unit_s * units * (1.0 + spectral)
        return (SAFETY * estimate + read_s) * self.pace.factor()

    def observe(self, task: Any, predicted: float, seconds: float) -> None:
        """A render predicted at ``predicted`` took ``seconds``; renders only, once calibrated
        (the built-in guess is several times too long: it would hold the average low)."""
        if self.calibrated and getattr(task, "variant", None) is not None:
            read_s = getattr(task, "read_s", 0.0)  # predicted without the safety factor
            self.pace.observe((predicted / self.pace.factor() - read_s) / SAFETY + read_s,
                              seconds)

    def _slowest(self) -> Coefficients:
        """What a label with no timing of its own is priced by: the slowest calibrated
        label, or the built-in guess while a part of the calibration is still out (the
        parts in may all be cheap presets)."""
        if not self.calibrated or not self.labels:
            return Coefficients(DEFAULT_PER_UNIT_S, DEFAULT_PER_WAVELENGTH)
        return Coefficients(max(c.per_unit_s for c in self.labels.values()),
                            max(c.per_wavelength for c in self.labels.values()))

    def _slowest_cold(self) -> float:
        """The first-render cost of a label with none of its own: the slowest measured,
        and not under the built-in guess while a part of the calibration is still out."""
        measured = list(self.cold.values())
        return max(measured if self.calibrated else [*measured, DEFAULT_COLD_S],
                   default=DEFAULT_COLD_S)

    def calibrate(self, report: bytes) -> None:
        """Fit the coefficients from a ``CalibrateTask``'s JSON answer, one part of the
        calibration (the whole where it names none): calibrated once every part is in."""
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
        cold = {label: max(0.0, float(s)) for label, s in data.get("cold_s", {}).items()}
        loads = {label: max(1.0, float(n)) for label, n in data.get("light_load", {}).items()}
        with self._lock:
            # Each part times the overhead again; the largest stands, as it adds to every job.
            self.overhead_s = max(overhead, self.overhead_s) if self._parts else overhead
            self._parts.add(int(data.get("part", 0)))
            self.labels.update(labels)
            self.cold.update(cold)
            self.light_load.update(loads)
            self.calibrated = len(self._parts) >= int(data.get("parts", 1))
            self.calibration_wavelengths = int(wavelengths)

    def describe(self) -> dict[str, object]:
        with self._lock:
            return {"calibrated": self.calibrated, "overhead_s": round(self.overhead_s, 5),
                    "labels": {k: {"per_unit_s": c.per_unit_s, "per_wavelength": c.per_wavelength}
                               for k, c in self.labels.items()}}


def shading_index(iridescence: str, orders: int, stack_pairs: int = 0,
                  coated: bool = False) -> float:
    """Shading cost per pixel-sample-wavelength over the paper's rotations', measured on
    llvmpipe at 0, 16 and 128 wavelengths: a thin film 0.5-1.8× (dearest without
    wavelengths, where it is cheap), a grating of m orders 2.3-3.3× (m = 1), 4.1-5.4× (3),
    6.6-10× (8); the safety factor covers the spread. A stack of N pairs, over the single
    film (oil-film, draft, one sample, at 0, 16 and 64 wavelengths): 1.4-1.8× (N = 1),
    2.2-3.8× (4), 8.8-15.6× (16), inside 1 + N. A clear coat, over the same material
    uncoated (256², draft and standard, the key light and the studio): 0.87-1.29×
    over two runs (bench/coat_cost.py)."""
    coat = COAT_COST if coated else 1.0
    if iridescence == "grating":
        return coat * (2.0 + orders)
    return coat * (1.25 * (1 + stack_pairs) if iridescence == "thin-film" else 1.0)


def mesh_cost_s(size_bytes: int, max_triangles: int, passes: int) -> tuple[float, float]:
    """Seconds a render spends on a mesh file besides shading: its read (a worker keeps a
    few read, but admission cannot know which) and its triangles drawn in every pass."""
    triangles = min(max_triangles, size_bytes // MIN_BYTES_PER_TRIANGLE)
    return CHECK_S_PER_BYTE * size_bytes, TRIANGLE_PASS_S * triangles * passes


def check_cost_s(size_bytes: float) -> float:
    """Predicted seconds of a mesh check of a ``size_bytes`` file, up to its time limit."""
    return min(CHECK_TIME_LIMIT_S, SAFETY * (CHECK_BASE_S + CHECK_S_PER_BYTE * size_bytes))


RENDER_ADVICE = "lower width, height, samples or wavelengths (or choose a lower quality)"
PLOT_ADVICE = "lower size or wavelengths"
CHECK_ADVICE = ("send a smaller file (fewer triangles; GLB or binary PLY read fastest), or "
                "ask the operator for a longer OPALINE_DEADLINE_S")


def admit(predicted: float, workers: int, running: Sequence[float], queued: Sequence[float],
          queue_size: int, deadline_s: float, label: str = "",
          task: object = None) -> Exception | None:
    """Why a job predicted to take ``predicted`` seconds cannot be taken now, or None.

    ``running``: the predicted seconds left of each job being rendered; ``queued``:
    the predictions of the jobs waiting. The work ahead is shared by the workers. ``label``:
    the job's, so that a refusal's advice fits it (a mesh check is no render); ``task``:
    the job's, whose own ``advice()`` (what to lower, the request fields it names) a
    refusal gives where it has one."""
    if not workers:
        return Unavailable("no render worker has a GL context (the server log says why)")
    if predicted > deadline_s:
        what, default = {CHECK_LABEL: ("checking this mesh file", CHECK_ADVICE),
                        MDF_LABEL: ("this plot", PLOT_ADVICE)}.get(
                            label, ("this request", RENDER_ADVICE))
        advice: Callable[[float], tuple[str, list[str]]] | None = getattr(task, "advice", None)
        advice_text, fields = advice(predicted) if advice is not None else (default, [])
        return TooSlow(f"{what} is predicted to take {predicted:.1f} s, over the "
                       f"{deadline_s:g} s limit: {advice_text}", fields)
    backlog = (sum(running) + sum(queued)) / workers
    if len(queued) >= queue_size or backlog + predicted > deadline_s:
        return Overloaded(f"{len(queued)} jobs are waiting, about {backlog:.1f} s of work",
                          retry_after_s=max(1.0, backlog))
    return None
