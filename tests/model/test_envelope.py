"""The multi-peak lobe's envelope and filtered bands (opaline/model/envelope.py) against
independent quadratures: the albedo's closed form and Schlick fit, the bound that decides
whether band samples are drawn, and the band filter's limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.model import envelope
from opaline.model.reference import mdf_multipeak

N_THETA, N_PHI = 1200, 600
TWO_PI = 2 * math.pi


def albedo_by_quadrature(nv: float, f0: float) -> float:
    """∫ D_env(h)·F(v·h)/(4·v·h·max(n·l, n·v))·n·l dω_l over a (θ, φ) grid of l: a
    different variable from the closed form's (the projected disc of h)."""
    theta = (np.arange(N_THETA) + 0.5) * (0.5 * math.pi / N_THETA)
    phi = (np.arange(N_PHI) + 0.5) * (2 * math.pi / N_PHI)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    l = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    v = np.array([math.sqrt(1 - nv * nv), 0.0, nv])
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    vh = h @ v
    d = 0.5 * np.maximum(h[..., 2], 0.0)
    fresnel = f0 + (1 - f0) * (1 - vh) ** 5
    f = d * fresnel / (4 * vh * np.maximum(l[..., 2], nv)) * l[..., 2]
    solid = np.sin(t) * (0.5 * math.pi / N_THETA) * (2 * math.pi / N_PHI)
    return float((f * solid).sum())


@pytest.mark.parametrize("f0", [1.0, 0.5, 0.04, 0.0])
@pytest.mark.parametrize("nv", [0.02, 0.1, 0.3, 0.5, 0.8, 1.0])
def test_albedo_matches_a_quadrature(nv, f0):
    expected = albedo_by_quadrature(nv, f0)
    # The closed form is exact (quadrature error ~1e-5); the Schlick part's fit within 7e-4.
    tolerance = 1e-4 if f0 == 1.0 else 1e-4 + 8e-4 * (1 - f0)
    assert abs(float(envelope.albedo(nv, f0)) - expected) <= tolerance


def test_dominant_direction_lies_between_n_and_the_mirror_direction():
    n = np.array([[0.0, 0.0, 1.0]])
    v = np.array([[0.6, 0.0, 0.8]])
    d = envelope.dominant(n, v)[0]
    r = np.array([-0.6, 0.0, 0.8])
    assert abs(np.linalg.norm(d) - 1.0) < 1e-12
    assert d @ n[0] > r @ n[0] and d @ r > n[0] @ r  # nearer each than the other is
    np.testing.assert_allclose(envelope.dominant(n, n), n, atol=1e-12)  # v = n: d = n


MATERIALS = [(8.5, 2.0, 1.2), (2.0, 1.0, 0.1), (30.0, 0.5, 3.0), (1.0, 0.0, 2.0),
             (0.0, 2.0, 1.2), (0.01, 2.0, 1.2), (0.05, 1.0, 1.0), (0.2, 0.0, 3.0), (3.0, 0.0, 0.0)]


@pytest.mark.parametrize("mu_f,alpha,beta", MATERIALS)
@pytest.mark.parametrize("per_wavelength", [1, 8, 64, 1024])
def test_bound_holds_wherever_bands_are_dropped(mu_f, alpha, beta, per_wavelength):
    """Where ``bands_resolved`` says no, what the samples would carry, the filtered band
    minus its mean, is under BAND_FLOOR at every h of the disc (checked on 250k points).
    (Where it says yes the bound is merely above the floor: it is a bound, and the bands
    may still be under it.)"""
    rng = np.random.default_rng(3)
    u = rng.random((250_000, 2))
    r, phi = np.sqrt(u[:, 0]), 2 * math.pi * u[:, 1]
    hx, hy = r * np.cos(phi), r * np.sin(phi)
    band = envelope.band_cell(hx, hy, mu_f, alpha, beta, envelope.cell_side(per_wavelength))
    if not envelope.bands_resolved(mu_f, alpha, beta, per_wavelength):
        cell = envelope.cell_side(per_wavelength)
        remainder = band - envelope.band_mean(mu_f, alpha, beta, cell)
        assert float(np.abs(remainder).max()) <= envelope.BAND_FLOOR


def test_presets_bands_drop_at_one_sample_and_return_with_many():
    assert not envelope.bands_resolved(8.5, 2.0, 1.2, 1)  # the sphere preset at draft, standard
    assert envelope.bands_resolved(8.5, 2.0, 1.2, 64)  # at the reference tier
    # No phase: the band is a constant 1, the envelope's, and nothing is left to sample.
    assert not envelope.bands_resolved(0.0, 2.0, 1.2, 1024)
    assert not envelope.bands_resolved(3.0, 0.0, 0.0, 1024)
    assert envelope.bands_resolved(0.2, 2.0, 1.2, 1)  # slow bands: what they add to it


@pytest.mark.parametrize("cycles", [0.0, 0.05, 0.3, 1.0, 2.7, 7.9])
def test_band_mean_is_the_disc_average(cycles):
    """Unfiltered (cell 0) round rings (α = β): the average of cos(2π·c·ρ) over the unit
    disc is 2·(cos a − 1)/a² + 2·sin a/a at a = 2π·c, in closed form; on stretched rings,
    filtered or not, a Monte Carlo average of band_cell over the disc agrees."""
    a = TWO_PI * cycles
    exact = 1.0 if a == 0 else 2 * (math.cos(a) - 1) / a**2 + 2 * math.sin(a) / a
    assert envelope.band_mean(cycles / 2.0, 4.0, 4.0) == pytest.approx(exact, abs=1e-9)
    if cycles * math.sqrt(2.0) > envelope.MEAN_CYCLES:
        return  # faded toward 0 there
    rng = np.random.default_rng(5)
    u = rng.random((400_000, 2))
    r, phi = np.sqrt(u[:, 0]), TWO_PI * u[:, 1]
    for cell in (0.0, 0.3, envelope.cell_side(1)):
        band = envelope.band_cell(r * np.cos(phi), r * np.sin(phi), cycles, 2.0, 0.5, cell)
        assert envelope.band_mean(cycles, 2.0, 0.5, cell) == pytest.approx(band.mean(), abs=4e-3)


def test_band_filter_tends_to_the_unfiltered_lobe():
    """As the cell shrinks, ½·hz·(band + 1) is eq. 4's multi-peak lobe."""
    rng = np.random.default_rng(4)
    hx, hy = rng.uniform(-0.7, 0.7, (2, 1000))
    hz = np.sqrt(np.clip(1 - hx * hx - hy * hy, 0, 1))
    band = envelope.band_cell(hx, hy, 8.5, 2.0, 1.2, 1e-9)
    np.testing.assert_allclose(0.5 * hz * (band + 1), mdf_multipeak(hx, hy, hz, 8.5, 2.0, 1.2),
                               atol=1e-12)
    # A cell over many bands leaves little of them.
    assert float(np.abs(envelope.band_cell(hx, hy, 8.5, 2.0, 1.2, 1.0)).mean()) < 0.05
