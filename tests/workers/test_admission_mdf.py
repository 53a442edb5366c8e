"""The MDF plot is priced by its own calibration, not as the slowest preset: a 384² plot at
128 wavelengths was refused as 21.5 s (too_slow) where it takes a few hundredths."""

from __future__ import annotations

import json
import time

import pytest

from opaline.model.params import Material
from opaline.workers.admission import MDF_LABEL, CostModel, admit
from opaline.workers.calibration import CALIBRATION_SAMPLES, CALIBRATION_SIZE, CalibrateTask
from opaline.workers.tasks import MdfTask

UNITS = CALIBRATION_SIZE * CALIBRATION_SIZE * CALIBRATION_SAMPLES
# A preset timed 100× dearer than a plot, as the dearest presets are.
SLOW_PRESET = {"overhead_s": 0.002, "units": UNITS, "wavelengths": 16,
               "timings": {"morpho": [0.5, 2.0]}}


def test_a_timed_plot_is_priced_by_its_own_timing():
    found = CostModel()
    found.calibrate(json.dumps({**SLOW_PRESET, "timings": {
        **SLOW_PRESET["timings"], MDF_LABEL: [0.005, 0.02]}}).encode())
    plot = MdfTask(Material(), 384, "png", 128).units()
    assert found.predict(*plot) < found.predict("morpho", *plot[1:]) / 20
    untimed = CostModel()
    untimed.calibrate(json.dumps(SLOW_PRESET).encode())
    assert untimed.predict(*plot) == pytest.approx(untimed.predict("morpho", *plot[1:]))


def test_a_plot_too_slow_is_told_to_lower_its_size():
    refusal = admit(20.0, 1, [], [], 8, 10.0, MDF_LABEL)
    assert refusal is not None and "lower size or wavelengths" in str(refusal)
    assert "samples" not in str(refusal)


@pytest.mark.gl
def test_the_calibration_times_the_plot_and_predicts_it_from_above(renderer):
    timings = CalibrateTask(0, 1)._time_plots(renderer, lambda: False, UNITS)
    found = CostModel()
    found.calibrate(json.dumps({**SLOW_PRESET, "timings": {MDF_LABEL: timings}}).encode())
    task = MdfTask(Material(mdf="multipeak"), 512, "png", 128)
    task.run(renderer, lambda: False)  # compiled outside the timing
    took = float("inf")  # the least of three: one timing on a shared machine can stall
    for _ in range(3):
        start = time.perf_counter()
        task.run(renderer, lambda: False)
        took = min(took, time.perf_counter() - start)
    predicted = found.predict(*task.units())
    # From above (its safety factor), and not hundreds of times over as before.
    assert took < predicted < 40 * took + 0.5
