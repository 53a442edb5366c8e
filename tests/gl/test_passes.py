"""Samples drawn as 2×2 grids in passes at twice the size (opaline.gl.passes)."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl import passes
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve


def test_plan_draws_multiples_of_four_at_twice_the_size():
    four = passes.plan(4, (256, 256))
    assert (four.factor, four.passes, four.samples) == (2, 1, 4)
    assert four.target_size((256, 128)) == (512, 256)
    sixteen = passes.plan(16, (128, 128))
    assert (sixteen.factor, sixteen.passes) == (2, 4)
    assert np.all(np.abs(sixteen.offsets) <= 0.5)  # each pass's jitter stays in a half-pixel cell
    assert passes.plan(2, (256, 256)).factor == 1 and passes.plan(2, (256, 256)).passes == 2
    assert passes.plan(4, (1024, 64)).factor == 1  # the 2× target would be over the limit
    assert passes.plan(1, (64, 64)).passes == 1


def test_downsample_sums_blocks():
    image = np.arange(4 * 6 * 2, dtype=np.float32).reshape(4, 6, 2)
    small = passes.downsample(image, 2)
    assert small.shape == (2, 3, 2)
    assert small[0, 0, 0] == image[0, 0, 0] + image[0, 1, 0] + image[1, 0, 0] + image[1, 1, 0]
    assert passes.downsample(image, 1) is image


@pytest.mark.gl
@pytest.mark.parametrize("name", ["sphere", "nacre"])
@pytest.mark.parametrize("fmt", ["png", "npy"])
def test_one_pass_at_twice_the_size_matches_four_jittered_passes(renderer, monkeypatch, name,
                                                                 fmt):
    """The 2×2 grid gives the 4-pass image within a fraction of a level on average; the
    normal map (nacre) is filtered over the image pixel, not the finer sample pixel."""
    # RGB: spectral samples are drawn a pass each (each integrates its own wavelengths).
    job = resolve(RenderRequest(preset=name, width=128, height=128, samples=4, wavelengths=0,
                                format=fmt),
                  get_preset(name))
    frame = renderer.render(job)
    monkeypatch.setattr(passes, "MAX_SUPERSAMPLED", 0)
    jittered = renderer.render(job)
    if fmt == "png":
        difference = np.abs(frame.pixels.astype(int) - jittered.pixels.astype(int)).mean()
        assert 0 < difference < 0.5, difference
    else:
        scale = float(jittered.linear[..., :3].mean())
        assert abs(float(frame.linear[..., 3].mean()) - float(jittered.linear[..., 3].mean())) < 0.01
        assert np.abs(frame.linear[..., :3] - jittered.linear[..., :3]).mean() < 0.1 * scale


@pytest.mark.gl
@pytest.mark.parametrize("name", ["sphere", "nacre", "cd-rom"])
@pytest.mark.parametrize("transparent", [False, True])
@pytest.mark.parametrize("tonemap", ["reinhard", "neutral"])
def test_one_sample_drawn_straight_to_bytes_matches_the_resolve(renderer, name, transparent,
                                                                tonemap):
    """A 1-sample 8-bit image is drawn and display-encoded by the surface pass itself;
    it is the resolve pass's image (the float path, quantised) within one level, right
    way up, with the same background or alpha."""
    from dataclasses import replace

    from opaline.output.encode import quantise

    job = resolve(RenderRequest(preset=name, width=96, height=64, quality="draft",
                                transparent=transparent, tonemap=tonemap, exposure=1.5),
                  get_preset(name))
    direct = renderer.render(job).pixels.astype(int)
    resolved = quantise(renderer.render(replace(job, format="png16")).display, 8).astype(int)
    assert direct.shape == (64, 96, 4 if transparent else 3)
    assert np.abs(direct - resolved[..., :direct.shape[2]]).max() <= 1
