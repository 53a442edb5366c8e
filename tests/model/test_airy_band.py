"""A conductor's film averaged across each wavelength's bin (model/airy_band.py): the
closed form is Airy's value at ρ = 1, the Poisson average of it by quadrature at any ρ,
the incoherent sum at ρ = 0; and it is what keeps 16 wavelengths from drawing a
micron-thick film on steel as false colour, where the bins' centres alone did."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model import metals, thinfilm
from opaline.model.airy_band import airy_band, bin_damping
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve


def random_interfaces(size: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    a = rng.uniform(-0.95, 0.95, size)
    b = rng.uniform(0.0, 0.98, size) * np.exp(1j * rng.uniform(-np.pi, np.pi, size))
    return a, b, rng.uniform(0.0, 2.0 * np.pi, size)


def test_at_rho_one_it_is_airys_value():
    a, b, phase = random_interfaces(2000, 1)
    np.testing.assert_allclose(airy_band(a, b, phase, 1.0), thinfilm.airy(a, b, phase),
                               rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("rho", [0.2, 0.6, 0.95])
def test_it_is_the_poisson_average_of_airys_value(rho):
    a, b, phase = random_interfaces(50, 2)
    t = 2.0 * np.pi * (np.arange(4096) + 0.5) / 4096
    kernel = (1.0 - rho**2) / (1.0 - 2.0 * rho * np.cos(t) + rho**2) / t.size
    averaged = thinfilm.airy(a[:, None], b[:, None], phase[:, None] + t) @ kernel
    np.testing.assert_allclose(airy_band(a, b, phase, rho), averaged, rtol=1e-9)


def test_at_rho_zero_it_is_the_incoherent_sum():
    a, b, phase = random_interfaces(500, 3)
    incoherent = a**2 + (1.0 - a**2) ** 2 * np.abs(b) ** 2 / (1.0 - a**2 * np.abs(b) ** 2)
    np.testing.assert_allclose(airy_band(a, b, phase, 0.0), incoherent, rtol=1e-12)


def test_the_damping_follows_the_phase_spread_over_the_bin():
    assert bin_damping(0.0, 500.0, 25.0) == 1.0
    thin, thick = bin_damping(2.0 * np.pi * np.array([0.5, 40.0]), 400.0, 25.0)
    assert thin > 0.99 and thick < 0.01
    # Where the samples are π apart in phase the first term would alias: mostly removed.
    assert bin_damping(np.pi * 16.0, 400.0, 25.0) == pytest.approx(np.exp(-1.0))


def steel_film(wavelengths: int, thickness: float, cos1: np.ndarray) -> np.ndarray:
    request = RenderRequest(preset="tempered-steel", film_thickness_max=thickness)
    material = resolve(request, get_preset("tempered-steel")).material
    nk = metals.substrate_for(material, wavelengths)
    return thinfilm.film_rgb_spectral(cos1, np.full_like(cos1, thickness), material.film_ior,
                                      nk, wavelengths)


@pytest.mark.parametrize("thickness", [1200.0, 2000.0])
def test_sixteen_wavelengths_of_a_thick_film_on_steel_are_not_false_colour(thickness):
    """Against 2048 wavelengths (the integral), over the angles: read at the 16 bins'
    centres, a film on steel was off by up to 0.135 in a channel at 1200 nm and 0.235 at
    2000 (0.037 and 0.076 on average: rings of false colour); averaged across each bin,
    0.022 and 0.002 at most, 0.006 and 0.001 on average."""
    cos1 = np.linspace(0.05, 1.0, 200)
    error = np.abs(steel_film(16, thickness, cos1) - steel_film(2048, thickness, cos1))
    print(f"{thickness} nm: channel error max {error.max():.4f}, mean {error.mean():.4f}")
    assert error.max() < 0.03 and error.mean() < 0.01
