"""The float64 stack (model/multilayer.py) held to what it must equal: colour-science's
``multilayer_tmm`` (Byrnes 2016, an implementation the project does not own) to 1e-9 in
reflectance and transmittance, s and p, over angles 0-84°, up to 32 layers; the single
film's Airy sum (model/thinfilm.py) on dielectrics and metals; R + T = 1 for lossless
stacks to 1e-12; zero-thickness layers as the bare interface; the quarter-wave Bragg
stack's closed form; total internal reflection, T = 0."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from opaline.model import metals, thinfilm
from opaline.model.multilayer import MAX_LAYERS, quarter_wave_peak, stack_optics

interference = pytest.importorskip("colour.phenomena.interference")

ANGLES = np.arange(0.0, 84.1, 12.0)
LAMBDAS = np.array([380.0, 470.0, 555.0, 640.0, 780.0])
RNG = np.random.default_rng(41)


def random_stack(count: int) -> tuple[np.ndarray, np.ndarray]:
    return RNG.uniform(1.0, 3.0, count), RNG.uniform(0.0, 500.0, count)


@pytest.mark.parametrize("count", [1, 2, 5, 12, MAX_LAYERS])
@pytest.mark.parametrize("substrate", [1.0, 1.52, 2.4])
def test_agrees_with_colour_science_to_1e_9(count, substrate):
    """A lossless stack (colour-science refracts with Re(ñ) and a real arcsin, which
    departs from the exact result under an absorbing medium at oblique incidence: see
    tests/model/test_thin_film_tmm.py; metals are held to the Airy sum below)."""
    layers, thicknesses = random_stack(count)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r, t = interference.multilayer_tmm([1.0, *layers, substrate], thicknesses, LAMBDAS,
                                           ANGLES)
    cos0 = np.cos(np.radians(ANGLES))[None, :]
    ours = stack_optics(list(layers), thicknesses, LAMBDAS[:, None], cos0, 1.0, substrate)
    for got, theirs in ((ours.r_s, r[:, :, 0, 0]), (ours.r_p, r[:, :, 0, 1]),
                        (ours.t_s, t[:, :, 0, 0]), (ours.t_p, t[:, :, 0, 1])):
        np.testing.assert_allclose(got, theirs, rtol=0.0, atol=1e-9)


@pytest.mark.parametrize("film,substrate", [(1.33, 1.0), (1.45, 1.62), (2.4, 1.5),
                                            ("gold", None), ("titanium", None),
                                            ("bismuth", None)])
def test_one_layer_is_the_airy_sum(film, substrate):
    """A single film over a dielectric or a tabulated metal: the stack's R equals
    thinfilm.film_reflectance (Airy's sum of reflections: another derivation) to 1e-12."""
    lam = LAMBDAS[:, None]
    cos0 = np.cos(np.radians(ANGLES))[None, :]
    if isinstance(film, str):
        n_film, n_sub = 1.45, metals.metal_index(film, LAMBDAS)[:, None]
    else:
        n_film, n_sub = film, substrate
    for d in (0.0, 120.0, 640.0):
        ours = stack_optics([n_film], [d], lam, cos0, 1.0, n_sub)
        airy = thinfilm.film_reflectance(cos0, lam, d, n_film, n_sub)
        np.testing.assert_allclose(ours.reflectance, airy, rtol=0.0, atol=1e-12)


def test_lossless_stacks_conserve_energy_and_zero_layers_vanish():
    lam, cos0 = LAMBDAS[:, None], np.cos(np.radians(ANGLES))[None, :]
    layers, thicknesses = random_stack(MAX_LAYERS)
    optics = stack_optics(list(layers), thicknesses, lam, cos0, 1.0, 1.52)
    np.testing.assert_allclose(optics.r_s + optics.t_s, 1.0, atol=1e-12)
    np.testing.assert_allclose(optics.r_p + optics.t_p, 1.0, atol=1e-12)
    bare = stack_optics([], [], lam, cos0, 1.0, 1.52)
    zero = stack_optics(list(layers), np.zeros(MAX_LAYERS), lam, cos0, 1.0, 1.52)
    for got, want in ((zero.r_s, bare.r_s), (zero.r_p, bare.r_p), (zero.t_s, bare.t_s)):
        np.testing.assert_allclose(got, want, atol=1e-12)
    fresnel_s = ((cos0 - np.sqrt(1.52**2 - 1.0 + cos0**2)) / (cos0 + np.sqrt(1.52**2 - 1.0
                                                                          + cos0**2))) ** 2
    np.testing.assert_allclose(bare.r_s, np.broadcast_to(fresnel_s, bare.r_s.shape), atol=1e-12)


@pytest.mark.parametrize("pairs", [1, 4, 10])
def test_a_quarter_wave_bragg_stack_peaks_at_its_closed_form(pairs):
    design = 550.0
    n_high, n_low = 2.35, 1.38  # TiO2 / MgF2
    layers = [n_high, n_low] * pairs
    thicknesses = [design / (4.0 * n_high), design / (4.0 * n_low)] * pairs
    at_design = stack_optics(layers, thicknesses, design, 1.0, 1.0, 1.52)
    assert float(at_design.reflectance) == pytest.approx(
        quarter_wave_peak(n_high, n_low, pairs, 1.0, 1.52), abs=1e-12)
    # Its peak, not a point beside it: a little off the design wavelength reflects less.
    beside = stack_optics(layers, thicknesses, np.array([520.0, 580.0]), 1.0, 1.0, 1.52)
    assert np.all(beside.reflectance < at_design.reflectance)


def test_total_internal_reflection_transmits_nothing():
    """From glass (n 1.5) into air past the critical angle: R = 1, T = 0, whatever the
    film between, in s and p."""
    cos0 = np.cos(np.radians([45.0, 60.0, 84.0]))
    optics = stack_optics([1.38, 2.35], [100.0, 60.0], 550.0, cos0, 1.5, 1.0)
    np.testing.assert_allclose(optics.r_s, 1.0, atol=1e-12)
    np.testing.assert_allclose(optics.r_p, 1.0, atol=1e-12)
    np.testing.assert_allclose(optics.t_s, 0.0, atol=1e-12)


def test_too_many_layers_are_refused():
    with pytest.raises(ValueError, match="at most 32 layers"):
        stack_optics([1.5] * (MAX_LAYERS + 1), [10.0] * (MAX_LAYERS + 1), 550.0)
