"""The stack as a material's film (model/stack_film.py), held to what it must equal: one
pair with an empty spacer is the single film (the Airy sum of model/thinfilm.py, another
derivation, read at the bins' centres as the matrices are) on dielectrics and metals; all layers of thickness 0 leave the bare
substrate; the quarter-wave Bragg stack peaks at its closed form; a thickness field
swells the spacer with the film; grazing reflects all. The matrix itself is held to
colour-science in test_multilayer.py, and the shader to this twin in
tests/gl/test_stack_film.py."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model import metals, stack_film, thinfilm
from opaline.model.color_space import radiance_floor
from opaline.model.multilayer import quarter_wave_peak
from opaline.model.params import Material
from opaline.model.spectrum import rgb_weights, sample_wavelengths

COS = np.cos(np.radians(np.arange(0.0, 84.1, 6.0)))


def stack_material(**fields) -> Material:
    base = dict(iridescence="thin-film", film_stack_pairs=1, film_ior=1.8,
                film_thickness_max=300.0, film_spacer_ior=1.3, film_spacer_thickness=0.0,
                substrate_ior=1.5)
    return Material(**{**base, **fields})


@pytest.mark.parametrize("wavelengths", [0, 3, 16, 64])
@pytest.mark.parametrize("substrate", ["dielectric", "conductor"])
def test_one_pair_with_no_spacer_is_the_single_film(wavelengths, substrate):
    material = stack_material(substrate=substrate, metal="titanium")
    bins = stack_film.stack_bins(wavelengths)
    n_sub = metals.substrate_for(material, bins)
    for d in (0.0, 90.0, 480.0, 1500.0):
        ours = stack_film.stack_rgb(material, COS, np.full_like(COS, d), wavelengths)
        np.testing.assert_allclose(ours, single_film_at_points(material, d, n_sub, bins),
                                   rtol=0.0, atol=1e-12)


def single_film_at_points(material: Material, d: float, n_sub, bins: int) -> np.ndarray:
    """The single film read at each bin's centre, as the stack's matrices are (the single
    film's spectral path averages a metal's across each bin: model/airy_band.py)."""
    r = thinfilm.film_reflectance(COS[:, None], sample_wavelengths(bins), d, material.film_ior,
                                  n_sub)
    return radiance_floor(r @ rgb_weights(bins))


@pytest.mark.parametrize("substrate", ["dielectric", "conductor"])
def test_layers_of_no_thickness_leave_the_bare_substrate(substrate):
    material = stack_material(substrate=substrate, metal="gold", film_stack_pairs=9,
                              film_thickness_max=0.0, film_thickness_min=0.0,
                              film_spacer_thickness=0.0)
    ours = stack_film.stack_rgb(material, COS, np.zeros_like(COS), 16)
    bare = thinfilm.film_base_rgb(COS, metals.substrate_for(material, 16), 16)
    np.testing.assert_allclose(ours, bare, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("pairs", [1, 4, 8, 16])
def test_quarter_wave_stack_peaks_at_its_closed_form(pairs):
    """(HL)^N tuned to a bin's own wavelength: R there, at normal incidence, is
    ((1 − Y)/(1 + Y))², Y = (n_H/n_L)^(2N)·n_sub."""
    lam = sample_wavelengths(16)
    design = float(lam[7])
    material = stack_material(film_stack_pairs=pairs, film_ior=2.4,
                              film_thickness_max=design / (4 * 2.4),
                              film_spacer_ior=1.46, film_spacer_thickness=design / (4 * 1.46),
                              substrate_ior=1.52)
    r = stack_film.stack_reflectance(material, 1.0, material.film_thickness_max, 16)
    expected = quarter_wave_peak(2.4, 1.46, pairs, substrate=1.52)
    assert abs(r[7] - expected) < 1e-12
    assert r[7] == r.max()  # the design wavelength is the stop band's centre


def test_a_thickness_field_swells_the_whole_period():
    material = stack_material(film_stack_pairs=5, film_spacer_thickness=140.0)
    halved = stack_material(film_stack_pairs=5, film_spacer_thickness=70.0,
                            film_thickness_max=150.0)
    ours = stack_film.stack_rgb(material, COS, np.full_like(COS, 150.0), 32)
    explicit = stack_film.stack_rgb(halved, COS, np.full_like(COS, 150.0), 32)
    np.testing.assert_allclose(ours, explicit, rtol=0.0, atol=1e-12)


def test_grazing_reflects_everything():
    material = stack_material(film_stack_pairs=16)
    assert np.allclose(stack_film.stack_rgb(material, 0.0, 300.0, 16), 1.0, atol=1e-12)


def test_film_weight_mixes_with_the_bare_substrate():
    whole = stack_material(film_stack_pairs=3)
    half = stack_material(film_stack_pairs=3, film_weight=0.5)
    bare = thinfilm.film_base_rgb(COS, 1.5, 16)
    mixed = stack_film.stack_layer_rgb(half, COS, 300.0, 16)
    expected = 0.5 * (bare + stack_film.stack_rgb(whole, COS, 300.0, 16))
    np.testing.assert_allclose(mixed, expected, rtol=0.0, atol=1e-12)
