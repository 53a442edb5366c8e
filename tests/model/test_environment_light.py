"""Which way a job's environment lights it (opaline.model.environment_light): the map by
lobe samples, the multi-peak lobe split into envelope and bands, a grating's orders read
along their curve, or median-cut lights;
how many band samples a pass draws; what admission counts it as; and the rotation
source's own sample count."""

from __future__ import annotations

import math

import pytest

from opaline.model import environment_light as el
from opaline.model.params import RenderRequest
from opaline.model.request import resolve
from opaline.model.tiers import TIERS
from opaline.scene.bright import MAX_LIGHTS


def job(**fields):
    return resolve(RenderRequest(**{"preset": "sphere", "environment": "studio", **fields}))


def test_each_source_is_lit_the_way_it_measured_best():
    assert el.splits_lobe(job())  # the sphere preset: spectral multi-peak
    assert not el.splits_lobe(job(wavelengths=0)) and not el.reads_map(job(wavelengths=0))
    assert el.reads_map(job(mdf="ashikhmin")) and not el.splits_lobe(job(mdf="ashikhmin"))
    assert el.reads_map(job(iridescence="thin-film"))
    grating = job(iridescence="grating")
    assert el.reads_map(grating) and el.reads_orders(grating)
    assert not el.reads_orders(job(mdf="ashikhmin"))
    # The RGB fast path's grating places its orders by wavelength: median-cut lights.
    assert not el.reads_map(job(iridescence="grating", wavelengths=0))
    assert not el.reads_map(job(environment_lights=16))
    assert not el.reads_map(resolve(RenderRequest(preset="sphere")))  # no environment


def test_band_samples_are_drawn_only_where_the_pixel_resolves_the_bands():
    assert el.band_samples(job(), 6) == 0  # mu_f 8.5: grey at one sample a pixel
    slow = dict(mu_f=1.0, alpha=1.0, beta=1.0)
    assert el.band_samples(job(**slow), 6) == 16 // el.WAVELENGTHS_PER_SAMPLE
    assert el.band_samples(job(**slow), 2) == 2  # never more than the pass has
    assert el.band_samples(job(**slow, wavelengths=4), 6) == 1
    # Several passes: one a pass, carrying every wavelength.
    assert el.band_samples(job(quality="reference"), 16) == 1


def test_admission_counts_the_split_lobe_as_at_most_one_light_and_the_bright_ones():
    assert el.light_equivalents(job()) == MAX_LIGHTS  # no band samples drawn
    assert el.light_equivalents(job(mu_f=1.0, alpha=1.0, beta=1.0)) == 1 + MAX_LIGHTS
    assert el.light_equivalents(job(environment_lights=16)) == 16
    assert el.light_equivalents(job(iridescence="grating")) == 1 + MAX_LIGHTS
    # A request's own pieces are counted: 4096 of them cost about 410 lights.
    many = job(iridescence="grating", environment_samples=4096)
    assert el.light_equivalents(many) == math.ceil(4098 / 10) + MAX_LIGHTS
    standard = TIERS["standard"]
    assert el.light_equivalents(job(mdf="ashikhmin")) == (standard.environment_samples_rotation
                                                          + MAX_LIGHTS)


@pytest.mark.parametrize("tier", ["draft", "standard", "high", "reference"])
def test_the_rotation_source_and_gratings_get_their_own_sample_counts(tier):
    rotation = job(mdf="ashikhmin", quality=tier)
    film = job(iridescence="thin-film", quality=tier)
    grating = job(iridescence="grating", quality=tier)
    assert rotation.environment_sample_count == TIERS[tier].environment_samples_rotation
    assert film.environment_sample_count == TIERS[tier].environment_samples
    assert grating.environment_sample_count == TIERS[tier].environment_samples_grating
    assert job(mdf="ashikhmin", environment_samples=5).environment_sample_count == 5
    assert TIERS["standard"].environment_samples_rotation % 3 == 0  # a third a lobe
