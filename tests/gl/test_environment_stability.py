"""Stability of environment light (issue 21's Done means): maps with a 1e5:1 dynamic
range, all black, a single bright texel, and NaN/Inf/negative/float-max texels in a
user's file (sanitised on reading: scene/environments.py) render every colour source
and MDF at draft, standard and high as linear float (format=npy) with 0 non-finite
pixels; black lights nothing, one texel lights within the estimator's bound.

The maps are environment_cases.ENVIRONMENT_MAPS, written as .exr/.hdr files into a
temporary environments folder that the session's renderer reads.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from environment_cases import BRIGHT_TEXEL, ENVIRONMENT_MAPS, write_environment
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from radiance_checks import is_radiance, radiance_problems
from stability_cases import EXTREMES

pytestmark = pytest.mark.gl

SIZE = 32
TIERS = ("draft", "standard", "high")
SOURCES = {
    "rotation-ashikhmin": dict(mdf="ashikhmin", ex=300.0, ey=30.0, theta1=0.5, theta2=1.0,
                               kd=0.2),
    "rotation-ashikhmin-1e6": dict(mdf="ashikhmin", ex=1e6, ey=1e6, kd=0.0),
    "rotation-multipeak": dict(mdf="multipeak", kd=0.2),
    "thin-film": dict(iridescence="thin-film", ex=500.0, ey=500.0),
    "grating": dict(iridescence="grating"),  # its orders read along their curve
}
# A lobe sample's weight f·cos/pdf is at most ks·3 for the rotation mixture (one lobe
# over the three lobes' mean) and ks·π for the disc (D ≤ hz); a thin film's reflectance
# is under 1. The diffuse term of one texel of solid angle Ω: kd·albedo·E/π, E ≤ B·Ω.
WEIGHT_BOUND = math.pi


@pytest.fixture(scope="module")
def environments(renderer, tmp_path_factory):
    """The maps' file names, in a folder the session's renderer reads for this module."""
    folder = tmp_path_factory.mktemp("environments")
    names = {name: write_environment(folder, name) for name in ENVIRONMENT_MAPS}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(renderer.environments, "environments_dir", folder)
        yield names


def render(renderer, environment: str, tier: str, fmt: str = "npy", **fields):
    preset = get_preset("sphere")
    request = RenderRequest(preset="sphere", width=SIZE, height=SIZE, format=fmt,
                            quality=tier, environment=environment, **fields)
    job = resolve(request, preset)
    return job, renderer.render(job, preset=preset)


def assert_finite(image: np.ndarray, what: str) -> None:
    bad = ~np.isfinite(image)
    assert not bad.any(), f"{what}: {int(bad.sum())} non-finite values at {np.argwhere(bad)[:3]}"
    assert is_radiance(image), f"{what}: {radiance_problems(image)}"


@pytest.mark.parametrize("tier", TIERS)
@pytest.mark.parametrize("source", list(SOURCES))
@pytest.mark.parametrize("name", list(ENVIRONMENT_MAPS))
def test_every_source_renders_finite_under_extreme_maps(renderer, environments, name,
                                                        source, tier):
    job, frame = render(renderer, environments[name], tier, **SOURCES[source])
    image = frame.linear
    assert_finite(image, f"{name} {source} {tier}")
    covered = image[..., 3] > 0.5
    assert covered.mean() > 0.2, "the object was drawn"
    rgb = image[..., :3][covered]
    if name == "black":
        # Median-cut lights (the grating's) keep the preset's ambient term; a map, nothing.
        ambient = 0.0
        if source == "grating":
            ambient = max(get_preset("sphere").ambient) * job.material.kd * max(job.material.albedo)
        assert rgb.max() <= ambient * (1 + 1e-6), f"a black map lit the object: max {rgb.max()}"
    if name == "single-texel" and source != "grating":
        material = job.material
        bound = BRIGHT_TEXEL * (WEIGHT_BOUND * material.ks + material.kd * max(material.albedo))
        assert rgb.max() <= bound, f"one texel of {BRIGHT_TEXEL} gave {rgb.max()}"


@pytest.mark.parametrize("extreme", ["ashikhmin:all-max", "multipeak:all-max"])
@pytest.mark.parametrize("name", ["nan-inf", "rgbe-huge", "range-1e5"])
def test_everything_at_an_end_under_a_broken_map(renderer, environments, name, extreme):
    """Every range at its end (exponents, ks, kd, intensity, exposure) under the clamped
    maximum: linear output finite, and the ACES display encoding (x² in fp32) too."""
    fields = {**EXTREMES[extreme].model_dump(), "environment_intensity": 1000.0}
    _, frame = render(renderer, environments[name], "high", **fields)
    assert_finite(frame.linear, f"{name} {extreme} npy")
    _, frame = render(renderer, environments[name], "high", "png16", tonemap="aces",
                      exposure=1000.0, **fields)
    assert_finite(frame.display, f"{name} {extreme} png16")
