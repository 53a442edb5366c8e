"""More samples, more wavelengths and the analytic filter each buy accuracy (docs/design.md §8).

On cd-rom (mu_f 8.5: rings a few pixels wide at 128²), each knob is turned
while the others stay fixed, and the error against a brute-force image of the
same model must fall. If samples, wavelengths or the analytic band-limit were
ignored, two settings would give the same image and a strict comparison fails.
The metrics are the benchmark's (bench/metrics.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from bench_metrics import metrics
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve

pytestmark = pytest.mark.gl
pytest.importorskip("flip_evaluator")

PRESET = "cd-rom"
SIZE = 128
MANY_SAMPLES = 256  # brute-force reference in the image plane (wavelengths 0, aa none)
MANY_WAVELENGTHS = 128  # spectral reference, at the same samples as the renders it judges




def render(renderer, preset: str = PRESET, size: int = SIZE, **fields) -> np.ndarray:
    fields.setdefault("format", "png16")  # float display values, not 8-bit pixels
    request = RenderRequest(preset=preset, width=size, height=size, **fields)
    frame = renderer.render(resolve(request, get_preset(preset)))
    return frame.linear if frame.linear is not None else frame.display


@pytest.fixture(scope="module")
def brute_force(renderer) -> np.ndarray:
    """The RGB model converged over the pixel: many samples, no analytic filter."""
    return render(renderer, samples=MANY_SAMPLES, wavelengths=0, aa="none")


def test_error_falls_as_samples_rise(renderer, brute_force):
    """Against a 256-sample image, 1 → 4 → 16 samples strictly raise PSNR and lower FLIP."""
    # A sample pattern whose mean is off the pixel centre shifts the image by a fraction of a
    # pixel, which on fine rings costs more than the extra samples gain: FLIP catches it.
    images = [render(renderer, samples=n, wavelengths=0, aa="none") for n in (1, 4, 16)]
    psnr = [metrics.psnr(brute_force, image) for image in images]
    flip = [metrics.flip(brute_force, image) for image in images]
    assert psnr[0] < psnr[1] < psnr[2], f"PSNR at 1, 4, 16 samples: {psnr}"
    assert flip[0] > flip[1] > flip[2], f"FLIP at 1, 4, 16 samples: {flip}"


def test_error_falls_as_wavelengths_rise(renderer):
    """Against 128 wavelengths, 4 → 8 → 32 wavelengths at 4 samples strictly lower ΔE00 and FLIP."""
    fields = {"samples": 4, "aa": "analytic"}
    reference = render(renderer, wavelengths=MANY_WAVELENGTHS, **fields)
    images = [render(renderer, wavelengths=n, **fields) for n in (4, 8, 32)]
    delta_e = [metrics.delta_e2000_stats(reference, image)[0] for image in images]
    flip = [metrics.flip(reference, image) for image in images]
    assert delta_e[0] > delta_e[1] > delta_e[2], f"ΔE00 mean at 4, 8, 32 wavelengths: {delta_e}"
    assert flip[0] > flip[1] > flip[2], f"FLIP at 4, 8, 32 wavelengths: {flip}"


def test_analytic_filter_beats_one_plain_sample(renderer, brute_force):
    """At 1 sample, the analytic band-limit's FLIP against brute force is at least 10% lower."""
    plain = metrics.flip(brute_force, render(renderer, samples=1, wavelengths=0, aa="none"))
    filtered = metrics.flip(brute_force,
                            render(renderer, samples=1, wavelengths=0, aa="analytic"))
    assert filtered < 0.9 * plain, f"FLIP analytic {filtered:.4f}, none {plain:.4f}"


@pytest.mark.parametrize("preset", ["oil-slick"])
def test_one_analytic_sample_beats_four_plain_samples(renderer, preset):
    """On the presets whose error is the fine bands themselves, one sample with the 2-D box
    filter beats four plain samples against the same (RGB) model converged. (On cd-rom it
    does not: there the error left is the disc's silhouette, which no shading filter
    touches; docs/accuracy.md. On the sphere it tied 4 jittered passes and loses narrowly,
    0.0058 against 0.0056, to the 2×2 grid that draws four samples in one pass.)"""
    converged = render(renderer, preset, samples=MANY_SAMPLES, wavelengths=0, aa="none")
    one = metrics.flip(converged, render(renderer, preset, samples=1, wavelengths=0,
                                         aa="analytic"))
    four = metrics.flip(converged, render(renderer, preset, samples=4, wavelengths=0, aa="none"))
    assert one < four, f"{preset}: FLIP 1 spp analytic {one:.4f}, 4 spp none {four:.4f}"


@pytest.mark.parametrize(("preset", "fields"), [
    ("cd-rom", {"samples": 2, "wavelengths": 0, "aa": "analytic"}),
    ("cd-rom", {"samples": 2, "wavelengths": 8, "aa": "none"}),
    ("cd-rom-ashikhmin", {"samples": 2, "wavelengths": 0, "aa": "none"}),
    ("nacre", {"samples": 2, "wavelengths": 8, "aa": "analytic"}),
    ("sphere", {"samples": 2, "wavelengths": 0, "aa": "none"}),
])
def test_all_features_program_gives_the_scene_variants_image(renderer, preset, fields):
    """The all-features program draws the scene variant's linear image, within 1e-5."""
    request = RenderRequest(preset=preset, width=64, height=64, format="npy", **fields)
    job = resolve(request, get_preset(preset))
    own = renderer.render(job).linear
    every = renderer.render(job, all_features=True).linear
    difference = float(np.abs(every - own).max())
    assert difference <= 1e-5, f"max |all-features − own| = {difference:.3g}"
