"""The map samples of the rotation source, of a film and of a rough clear coat pooled over
each 2×2 quad of pixels (ENV_QUAD_MEAN and COAT_QUAD_MEAN in
glsl/lib/environment_light.glsl and lib/environment_coat.glsl) against its float64 twin,
``lobe_sampling.quad_means``. On a lobe far wider than a pixel's step (pooled in full)
the same render without the pooling, averaged quad by quad, must give the pooled render
where all four pixels of a quad lie on one triangle (the driver shades a quad once per
triangle it touches, the others' pixels as helpers: there the mean takes their values
extended from the triangle's plane). The driver's derivatives have to be fine ones (each
row its own difference) for that to hold. On a mirror (a lobe narrower than a pixel's
step, not pooled) the two renders must be the same."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl import environment_light, passes
from opaline.model.lobe_sampling import quad_means
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve

SIZE = 128
# The neutral map has no bright feature split off as a light, and kd = 0 no diffuse term:
# the image is the map's specular reflection alone, which the quad mean pools. The disc
# is flat, so the mirror direction steps little from pixel to pixel.
SCENE = "cd-rom-ashikhmin"
ON_ONE_TRIANGLE = 0.95  # the share of covered quads inside one triangle
ROTATION = {"mdf": "ashikhmin", "ex": 4.0, "ey": 40.0, "theta1": 0.5, "theta2": 1.0,
            "kd": 0.0}
MIRROR = {**ROTATION, "ex": 1e6, "ey": 1e6}


def render(renderer, **fields) -> np.ndarray:
    preset = get_preset(SCENE)
    request = RenderRequest(preset=SCENE, width=SIZE, height=SIZE, format="npy",
                            environment="neutral", transparent=True, **{**ROTATION, **fields})
    frame = renderer.render(resolve(request, preset), preset=preset)
    assert frame.linear is not None
    return frame.linear.astype(np.float64)


def unpooled(monkeypatch) -> None:
    """The surface program compiled without the quad means (the material's lobe's and a
    clear coat's), all else the same."""
    defines = environment_light.defines

    def without_quad_mean(*args, **kwargs):
        found = defines(*args, **kwargs)
        return {**found, "ENV_QUAD_MEAN": False,
                **({"COAT_QUAD_MEAN": False} if "COAT_QUAD_MEAN" in found else {})}

    monkeypatch.setattr(environment_light, "defines", without_quad_mean)


FILM = {"iridescence": "thin-film", "film_ior": 1.33, "film_thickness_min": 300.0,
        "film_thickness_max": 600.0}
# A rough clear coat over nothing (ks = kd = 0): the image is the coat's reads alone.
COAT = {"ks": 0.0, "coat_weight": 1.0, "coat_roughness": 0.8, "coat_ior": 2.0}


@pytest.mark.parametrize("fields", [{"quality": "standard"}, {"quality": "draft"},
                                    {"quality": "standard", "wavelengths": 0},
                                    {"quality": "standard", **FILM},
                                    {"quality": "draft", **FILM},
                                    {"quality": "standard", **COAT}],
                         ids=["standard", "draft", "rgb", "film-standard", "film-draft",
                              "coat"])
def test_quad_mean_pools_each_quads_samples(renderer, monkeypatch, fields):
    pooled = render(renderer, **fields)
    with monkeypatch.context() as patch:
        unpooled(patch)
        each = render(renderer, **fields)
    covered = quad_means(each[..., 3:] >= 1.0)[..., 0] >= 1.0  # all four pixels on the object
    assert covered.sum() > SIZE * SIZE // 4, "the disc should cover most quads"
    expected = quad_means(each[..., :3])
    scale = float(np.abs(expected[covered]).max())
    error = np.abs(pooled[..., :3] - expected).max(-1)[covered] / scale
    assert np.mean(error <= 1e-5) >= ON_ONE_TRIANGLE, (
        f"{np.mean(error <= 1e-5):.1%} of the covered pixels at their quad's mean "
        f"(median error {np.median(error):.2g})")
    # Not vacuous: the unpooled pixels differ within their quads.
    assert np.abs(each[..., :3] - expected).max(-1)[covered].max() > 1e-2 * scale


def test_a_mirror_is_not_pooled(renderer, monkeypatch):
    """Its samples all read one direction: pooling would only blur the reflection."""
    pooled = render(renderer, quality="standard", **MIRROR)
    with monkeypatch.context() as patch:
        unpooled(patch)
        each = render(renderer, quality="standard", **MIRROR)
    np.testing.assert_array_equal(pooled, each)


def test_pooling_is_only_for_shared_lobe_samples(renderer):
    """The rotation source's and a film's few samples pool. The brute-force reference, a
    tier whose samples are not shared (high's 64), a grating's reads and the multi-peak
    bands read every pixel's own, as the lobe probe does."""
    preset = get_preset(SCENE)
    environment = renderer.environments.get("neutral")

    def pooled(quality: str, brute: bool = False, **fields) -> bool:
        request = RenderRequest(preset=SCENE, width=SIZE, height=SIZE, quality=quality,
                                environment="neutral", **{**ROTATION, **fields})
        job = resolve(request, preset)
        plan = passes.plan(job.samples, (SIZE, SIZE), grid=False)
        return bool(environment_light.defines(job, plan, environment, brute)["ENV_QUAD_MEAN"])

    assert pooled("standard") and pooled("draft") and pooled("standard", wavelengths=0)
    assert not pooled("standard", brute=True)
    assert not pooled("high")
    assert pooled("standard", **FILM) and pooled("draft", **FILM)
    assert pooled("standard", **{**FILM, "mdf": "multipeak"})  # a film's lobe is A-S
    assert not pooled("high", **FILM) and not pooled("standard", brute=True, **FILM)
    assert not pooled("standard", iridescence="grating")
    assert not pooled("standard", mdf="multipeak")
