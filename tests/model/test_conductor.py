"""Thin films on conductors in the float64 reference (issue 23, docs/physics.md §1.2).

The complex-Airy film against an independent characteristic-matrix solution
(Macleod's thin-film optics, its own convention n - ik, per polarisation, 1e-9),
its limits (k → 0 is the dielectric film, d → 0 the bare metal's Fresnel
reflectance), energy, Gulbrandsen's artist mapping, the tables' colours against
published F0, and the RGB fast path against the spectral one.
"""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model import metals, spectrum, thinfilm
from opaline.model.params import Material
from radiance_checks import is_radiance

METALS = tuple(metals.table()[1])


def macleod_reflectance(cos0, lam, d, n_film, n_sub, polarisation):
    """|r|² of air | film | substrate by characteristic matrices (Macleod, Thin-Film
    Optical Filters §2.2): N = n - ik, η = N·cos θ (s) or N/cos θ (p), δ = 2πN·d·cos θ/λ,
    [B, C] = [[cos δ, i sin δ/η1], [iη1 sin δ, cos δ]]·[1, η2], r = (η0B - C)/(η0B + C)."""
    sin0_sq = 1.0 - cos0**2

    def cos_in(n):  # Im(N cos θ) ≤ 0: the wave decays in Macleod's convention
        n_cos = np.sqrt(n * n - sin0_sq + 0j)
        n_cos = np.where(n_cos.imag > 0, -n_cos, n_cos)
        return n_cos / n

    def admittance(n):
        c = cos_in(n)
        return n * c if polarisation == "s" else n / c

    film, sub = n_film + 0j, np.conj(n_sub)
    delta = 2.0 * np.pi * film * d * cos_in(film) / lam
    eta0, eta1, eta2 = admittance(1.0 + 0j), admittance(film), admittance(sub)
    b = np.cos(delta) + 1j * np.sin(delta) / eta1 * eta2
    c = 1j * eta1 * np.sin(delta) + np.cos(delta) * eta2
    r = (eta0 * b - c) / (eta0 * b + c)
    return np.abs(r) ** 2


def ours_polarised(cos0, lam, d, n_film, n_sub):
    cos2, r12, r23, _ = thinfilm.interfaces(cos0, n_film, n_sub)
    phase = 4.0 * np.pi * n_film * d * cos2 / lam
    return [thinfilm.airy(a, b, phase) for a, b in zip(r12, r23, strict=True)]


def test_agrees_with_characteristic_matrices_both_polarisations():
    rng = np.random.default_rng(23)
    size = 20000
    cos0 = np.cos(np.radians(rng.uniform(0.0, 89.5, size)))
    lam = rng.uniform(380.0, 780.0, size)
    d = np.where(rng.random(size) < 0.1, 0.0, rng.uniform(0.0, 2000.0, size))
    n_film = rng.uniform(1.0, 3.0, size)
    n_sub = rng.uniform(0.05, 4.0, size) + 1j * rng.uniform(0.0, 10.0, size)
    ours = ours_polarised(cos0, lam, d, n_film, n_sub)
    for pol, value in zip("sp", ours, strict=True):
        assert np.abs(value - macleod_reflectance(cos0, lam, d, n_film, n_sub, pol)).max() < 1e-9


@pytest.mark.parametrize("name", METALS)
def test_tabulated_metals_agree_with_characteristic_matrices(name):
    lam = spectrum.sample_wavelengths(32)[:, None, None]
    nk = metals.metal_index(name, lam)
    cos0 = np.cos(np.radians(np.linspace(0.0, 89.0, 12)))[:, None]
    d = np.linspace(0.0, 600.0, 13)
    r = thinfilm.film_reflectance(cos0, lam, d, 2.4, nk)
    expected = 0.5 * sum(macleod_reflectance(cos0, lam, d, 2.4, nk, p) for p in "sp")
    assert np.abs(r - expected).max() < 1e-9


@pytest.mark.parametrize("n_sub", [1.0, 1.33, 1.52, 2.5, 4.0, 0.8])
def test_k_to_zero_is_the_dielectric_film(n_sub):
    """Below 1 (0.8): total internal reflection at the bottom, R = 1 either way."""
    cos1 = np.linspace(0.0, 1.0, 101)[:, None]
    lam = np.linspace(380.0, 780.0, 9)
    for d in (0.0, 120.0, 1500.0):
        dielectric = thinfilm.film_reflectance(cos1, lam, d, 1.45, n_sub)
        conductor = thinfilm.film_reflectance(cos1, lam, d, 1.45, np.complex128(n_sub))
        assert np.abs(conductor - dielectric).max() < 1e-12


def bare_conductor(cos0, nk):
    """Textbook Fresnel reflectance of air | metal, s and p averaged."""
    n_cos = np.sqrt(nk * nk - 1.0 + cos0**2 + 0j)
    rs = (cos0 - n_cos) / (cos0 + n_cos)
    rp = (nk * nk * cos0 - n_cos) / (nk * nk * cos0 + n_cos)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


@pytest.mark.parametrize("name", METALS)
@pytest.mark.parametrize("n_film", [1.0, 1.5, 3.0])
def test_zero_thickness_is_the_bare_metal(name, n_film):
    cos0 = np.linspace(0.0, 1.0, 51)[:, None]
    lam = spectrum.sample_wavelengths(16)
    nk = metals.metal_index(name, lam)
    r = thinfilm.film_reflectance(cos0, lam, 0.0, n_film, nk)
    assert np.abs(r - bare_conductor(cos0, nk)).max() < 1e-12
    assert np.allclose(r[-1], metals.bare_f0(nk), atol=1e-12)  # normal incidence


def test_energy_never_exceeds_one():
    rng = np.random.default_rng(5)
    size = 50000
    args = (rng.uniform(0.0, 1.0, size), rng.uniform(380.0, 780.0, size),
            rng.uniform(0.0, 2000.0, size), rng.uniform(1.0, 3.0, size),
            rng.uniform(0.0, 5.0, size) + 1j * rng.uniform(0.0, 10.0, size))
    r = thinfilm.film_reflectance(*args)
    assert np.all(np.isfinite(r)) and r.min() >= 0.0 and r.max() <= 1.0 + 1e-12
    for wavelengths in (0, 16):
        material = Material(iridescence="thin-film", substrate="conductor", metal="silver")
        rgb = thinfilm.film_rgb(args[0][:2000], args[2][:2000], 1.5,
                                metals.substrate_for(material, wavelengths), wavelengths)
        # Not ≤ 1 per channel: sRGB's colour weights go negative, so a spectrum under 1
        # (silver's, 0.97-0.99, with a film's ripple) may exceed 1 in one channel.
        assert is_radiance(rgb)  # a channel may go below 0 outside sRGB, its luminance not


@pytest.mark.parametrize("f0", [0.0, 0.04, 0.5, 0.9, 0.99])
def test_gulbrandsen_reproduces_f0_and_spans_the_edge_tint(f0):
    tint = np.linspace(0.0, 1.0, 11)
    nk = metals.gulbrandsen(f0, tint)
    assert np.allclose(metals.bare_f0(nk), f0, atol=1e-9)
    # Tint 0: the lossless dielectric of that F0 (n > 1, k = 0); tint 1: the least n.
    assert nk[0].imag == pytest.approx(0.0, abs=1e-6) and np.all(np.diff(nk.real) <= 1e-12)


def test_artist_metal_at_the_channels_is_its_f0():
    f0, tint = (0.9, 0.6, 0.3), (1.0, 0.8, 0.5)
    lam = metals.channel_wavelengths()
    assert np.allclose(metals.bare_f0(metals.artist_index(f0, tint, lam)), f0, atol=1e-9)


# Linear sRGB F0 of gold and copper as Real-Time Rendering (4th ed., Table 9.2,
# after Hoffman) lists them, from measured spectra; these tables under D65 differ from
# its data by up to 0.054 (gold's green: the n, k sources differ).
PUBLISHED_F0 = {"gold": (1.000, 0.782, 0.344), "copper": (0.955, 0.638, 0.538)}


@pytest.mark.parametrize("name", sorted(PUBLISHED_F0))
def test_bare_metal_colour_is_the_published_f0(name):
    material = Material(iridescence="thin-film", substrate="conductor", metal=name,
                        film_thickness_max=0.0)
    spectral = thinfilm.film_rgb(1.0, 0.0, 1.5, metals.substrate_for(material, 128), 128)
    fast = thinfilm.film_rgb(1.0, 0.0, 1.5, metals.substrate_for(material, 0), 0)
    assert np.abs(spectral - PUBLISHED_F0[name]).max() < 0.06
    assert np.abs(fast - PUBLISHED_F0[name]).max() < 0.07
    assert spectral[0] > spectral[1] > spectral[2]  # warm: red, then green, least blue


@pytest.mark.parametrize(("name", "mean_bound"), [("gold", 0.035), ("copper", 0.027),
                                                  ("titanium", 0.006), ("iron", 0.006)])
def test_fast_path_against_the_spectral_path(name, mean_bound):
    """The measured mean |fast - spectral(256)| in linear RGB over films 0-600 nm of
    index 1.5 and 2.4 at v·h 0.05-1 (docs/physics.md §1.2), under D65: gold 0.026/0.032,
    copper 0.016/0.024, titanium 0.002/0.004, iron 0.001/0.002."""
    cos1, d = np.meshgrid(np.linspace(0.05, 1.0, 20), np.linspace(0.0, 600.0, 61))
    material = Material(iridescence="thin-film", substrate="conductor", metal=name)
    for n_film in (1.5, 2.4):
        spectral = thinfilm.film_rgb(cos1, d, n_film, metals.substrate_for(material, 256), 256)
        fast = thinfilm.film_rgb(cos1, d, n_film, metals.substrate_for(material, 0), 0)
        assert np.abs(fast - spectral).mean() < mean_bound


def test_the_tables_cover_the_visible_range_and_cite_their_sources():
    grid, table = metals.table()
    assert grid[0] == 380.0 and grid[-1] == 780.0 and len(grid) == 41
    header = metals.TABLE_FILE.read_text()
    for name, nk in table.items():
        assert np.all(nk.real > 0.0) and np.all(nk.imag > 0.0)
        assert f"#   {name}: " in header
