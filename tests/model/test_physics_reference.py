"""The float64 references of the physical sources against closed forms (issue 14).

Thin film: thickness 0 is the bare substrate's Fresnel reflectance, a quarter-wave
film at normal incidence has the textbook minimum, energy never exceeds 1, total
internal reflection reflects everything, and the fast (Belcour-Barla) path stays
close to the converged spectral integral. Grating: the Bessel series matches
SciPy, the efficiencies of all orders sum to 1, and the first order's peak
wavelength is where the grating equation puts it, within the lobe's width.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import jv

from opaline.model import grating, thinfilm, visible
from opaline.model.params import Material
from opaline.model.reference import shading_frame
from radiance_checks import is_radiance


def fresnel_unpolarised(cos_i, n1, n2):
    """Textbook Fresnel reflectance of a bare interface (s and p averaged)."""
    sin_t = n1 / n2 * np.sqrt(1.0 - cos_i**2)
    cos_t = np.sqrt(1.0 - sin_t**2)
    rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
    rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t)
    return 0.5 * (rs**2 + rp**2)


@pytest.mark.parametrize("n_film", [1.0, 1.33, 1.5, 2.4, 3.0])
@pytest.mark.parametrize("n_sub", [1.0, 1.33, 1.52, 4.0])
def test_zero_thickness_is_the_bare_substrate(n_film, n_sub):
    cos1 = np.linspace(1e-3, 1.0, 101)  # exactly grazing on n = 1 is 0/0 in the textbook form
    lam = np.linspace(380.0, 780.0, 7)[:, None]
    r = thinfilm.film_reflectance(cos1, lam, 0.0, n_film, n_sub)
    assert np.allclose(r, fresnel_unpolarised(cos1, 1.0, n_sub), atol=1e-12)


@pytest.mark.parametrize(("n_film", "n_sub"), [(1.38, 1.52), (1.33, 1.0), (1.5, 1.33), (2.0, 4.0)])
def test_quarter_wave_at_normal_incidence(n_film, n_sub):
    """n·d = λ/4: R = ((n_sub - n_film²)/(n_sub + n_film²))², an extremum in d."""
    lam = 550.0
    d = lam / (4.0 * n_film)
    expected = ((n_sub - n_film**2) / (n_sub + n_film**2)) ** 2
    assert thinfilm.film_reflectance(1.0, lam, d, n_film, n_sub) == pytest.approx(expected, abs=1e-14)
    around = thinfilm.film_reflectance(1.0, lam, d * np.array([0.97, 1.03]), n_film, n_sub)
    bare = fresnel_unpolarised(1.0, 1.0, n_sub)
    # Film index between air and substrate: the quarter wave is the anti-reflection
    # minimum; above both (oil on water, soap): a maximum.
    if 1.0 < n_film < n_sub:
        assert expected < bare and np.all(around > expected)
    elif n_film > max(1.0, n_sub):
        assert expected > bare and np.all(around < expected)


def test_energy_never_exceeds_one_and_tir_reflects_all():
    rng = np.random.default_rng(14)
    cos1 = rng.uniform(0.0, 1.0, 20000)
    lam = rng.uniform(380.0, 780.0, 20000)
    d = rng.uniform(0.0, 2000.0, 20000)
    n_film = rng.uniform(0.5, 3.0, 20000)  # below 1: total internal reflection at the top
    n_sub = rng.uniform(0.5, 4.0, 20000)  # below 1: at the bottom
    r = thinfilm.film_reflectance(cos1, lam, d, n_film, n_sub)
    assert np.all(np.isfinite(r)) and r.min() >= 0.0 and r.max() <= 1.0 + 1e-12
    sin1 = np.sqrt(1.0 - cos1**2)
    tir = (sin1 > n_film) | (sin1 > n_sub)
    assert tir.sum() > 1000 and np.all(r[tir] == 1.0)
    for wavelengths in (0, 16):
        rgb = thinfilm.film_rgb(cos1[:2000], d[:2000], 1.5, 0.8, wavelengths)
        assert is_radiance(rgb)


def test_grazing_reflects_everything():
    r = thinfilm.film_reflectance(0.0, 500.0, np.array([0.0, 300.0]), 1.5, 1.33)
    assert np.allclose(r, 1.0)
    assert np.allclose(thinfilm.film_rgb_fast(np.array([0.0]), 300.0, 1.5, 1.33), 1.0, atol=1e-9)


def test_spectral_integral_converges():
    """128 wavelengths (3.1 nm bins) against 400 (1 nm): the ground truth is converged."""
    cos1 = np.linspace(0.05, 1.0, 40)[:, None]
    d = np.linspace(0.0, 1500.0, 60)[None, :]
    fine = thinfilm.film_rgb_spectral(cos1, d, 1.33, 1.0, 400)
    coarse = thinfilm.film_rgb_spectral(cos1, d, 1.33, 1.0, 128)
    assert np.abs(coarse - fine).max() < 2e-3


def test_fast_path_is_close_to_the_spectral_integral():
    """Belcour-Barla with our three-Gaussian fit, against the converged colour, for
    films up to 1 µm: within 0.006 (reflectances up to ~0.4) while v·h ≥ 0.3. Nearer
    grazing the Fourier series of a soap film (|r12·r23| → 1) converges slowly and
    the fast path errs up to ~0.2 at v·h = 0.02 (docs/physics.md)."""
    cos1 = np.linspace(0.3, 1.0, 36)[:, None]
    d = np.linspace(0.0, 1000.0, 101)[None, :]
    for n_film, n_sub in ((1.5, 1.33), (1.33, 1.0), (1.3, 1.5), (2.4, 1.5)):
        fast = thinfilm.film_rgb_fast(cos1, d, n_film, n_sub)
        exact = thinfilm.film_rgb_spectral(cos1, d, n_film, n_sub, 128)
        err = np.abs(fast - exact).max()
        print(f"fast vs spectral, film {n_film} on {n_sub}: max |Δ| {err:.4f}")
        assert err < 0.006


@pytest.mark.parametrize(("n_film", "n_sub"), [(1.33, 1.0), (1.5, 1.33), (3.0, 1.0)])
def test_fast_path_at_zero_thickness_is_the_bare_substrate(n_film, n_sub):
    """The series' tail is summed in closed form, so even where |r12·r23| nears 1
    (grazing on a soap film) a film of thickness 0 leaves the substrate's Fresnel."""
    cos1 = np.linspace(1e-3, 1.0, 200)
    fast = thinfilm.film_rgb_fast(cos1, 0.0, n_film, n_sub)
    bare = fresnel_unpolarised(cos1, 1.0, n_sub) if n_sub > 1.0 else 0.0 * cos1
    assert np.abs(fast - np.asarray(bare)[:, None]).max() < 1e-6


def test_fit_reproduces_the_colour_weights():
    """Each channel's Gaussians integrate to 1 (white stays white) and are within 3 %
    of the density's peak everywhere in the visible range."""
    assert np.allclose(visible.sensitivity(0.0, 0.0), 1.0)
    grid, table = visible.density_table()
    assert np.allclose(np.trapezoid(table, grid, axis=0), 1.0, atol=1e-9)
    # The same weights per µm⁻¹ of wavenumber, against the sum of the Gaussians.
    lam = np.arange(380.0, 781.0, 1.0)
    nu = 1000.0 / lam
    per_nu = visible.density_at(lam) * (lam[:, None] ** 2) / 1000.0
    g = visible.sensitivity_gaussians()
    model = sum(
        g[k, :, 0] / (g[k, :, 2] * np.sqrt(2 * np.pi))
        * np.exp(-((nu[:, None] - g[k, :, 1]) ** 2) / (2 * g[k, :, 2] ** 2))
        for k in range(g.shape[0])
    )
    assert np.all(np.abs(model - per_nu).max(axis=0) < 0.03 * per_nu.max(axis=0))


def test_packed_cumulative_is_the_table_linear_between_its_points():
    """The cumulative table as the shader reads it, a point and its step in one word a
    channel (16 bits each), is the table linear between its 5 nm points to within its
    quantisation, 0 at 380 nm, 1 at 780 nm and held beyond; continuous at every point."""
    grid, _ = visible.density_table()
    table = visible.cumulative_table()
    lam = np.linspace(300.0, 850.0, 22001)
    exact = np.stack([np.interp(lam, grid, table[:, c]) for c in range(3)], axis=-1)
    packed = visible.cumulative_at(lam)
    assert np.abs(packed - exact).max() < 3.1e-5
    assert np.abs(visible.cumulative_at([380.0, 780.0]) - [[0.0] * 3, [1.0] * 3]).max() < 3.1e-5
    # Either side of each interior point: the step ends where the next segment begins.
    left, right = visible.cumulative_at(grid[1:-1] - 1e-9), visible.cumulative_at(grid[1:-1])
    assert np.abs(left - right).max() < 5e-6
    assert visible.packed_cumulative().dtype == np.uint32


@pytest.mark.parametrize("m", range(0, 9))
def test_bessel_series_matches_scipy(m):
    x = np.linspace(0.0, 7.0, 141)
    assert np.allclose(grating.bessel_j(m, x), jv(m, x), rtol=0, atol=1e-12)


def shader_series(m: int, x: np.ndarray, terms: int) -> np.ndarray:
    """glsl/lib/grating.glsl bessel_j with BESSEL_TERMS = terms, in float64."""
    lead = (0.5 * x) ** m / math.factorial(m)
    y = -0.25 * x * x
    series = np.ones_like(x)
    for k in range(terms - 1, 0, -1):
        series = 1.0 + y * series / (k * (k + m))
    result: np.ndarray = lead * series
    return result


@pytest.mark.parametrize("tolerance", [grating.SERIES_TOLERANCE, grating.READS_SERIES_TOLERANCE])
@pytest.mark.parametrize("depth", [50.0, 120.0, 150.0, 250.0, 400.0])
def test_the_shaders_bessel_series_is_cut_within_its_tolerance(depth, tolerance):
    """bessel_terms(depth, tolerance) terms of J_m's series, over every argument the depth
    reaches (a ≤ π·depth·2/380 nm) and the orders the shader writes out: within the
    tolerance of J_m (the reads' 1e-6 cuts two terms at the CD's 150 nm), and one term
    fewer is not."""
    x = np.linspace(0.0, math.pi * depth * 2.0 / 380.0, 400)
    terms = grating.bessel_terms(depth, tolerance)
    worst = max(float(np.abs(shader_series(m, x, terms) - jv(m, x)).max()) for m in range(9))
    short = max(float(np.abs(shader_series(m, x, terms - 1) - jv(m, x)).max()) for m in range(9))
    assert worst <= tolerance < short


def test_efficiencies_of_all_orders_sum_to_one():
    lam = np.linspace(380.0, 780.0, 9)
    for depth in (0.0, 100.0, 400.0):
        total = sum(grating.efficiency(m, lam, depth, 2.0) for m in range(-25, 26))
        assert np.allclose(total, 1.0, atol=1e-9)


@pytest.mark.parametrize("pitch", [0.74, 1.6, 5.0])
@pytest.mark.parametrize("lam_target", [400.0, 550.0, 700.0])
def test_first_order_peaks_where_the_grating_equation_says(pitch, lam_target):
    """For a light and a view with (l + v)·t = 0, the first order's spectrum (η and
    lobe per wavelength) peaks at λ = d·(l + v)·b within the lobe's width in λ."""
    material = Material(iridescence="grating", ex=2000.0, ey=20000.0, grating_pitch=pitch)
    n = np.array([[0.0, 0.0, 1.0]])
    frame = shading_frame(n, np.array([[1.0, 0.0, 0.0]]))
    s = lam_target / (1000.0 * pitch)  # the (l + v)·b the equation asks for
    lb, vb = 0.5 * s - 0.2, 0.5 * s + 0.2  # both above the horizon for every case here
    l = np.array([[0.0, lb, math.sqrt(1.0 - lb * lb)]])
    v = np.array([[0.0, vb, math.sqrt(1.0 - vb * vb)]])
    lam = np.arange(380.0, 780.0, 0.25)
    spectrum = np.array([grating.order_term(material, frame, l, v, 1, x)[0] for x in lam])
    peak = lam[int(spectrum.argmax())]
    k_len = float(np.linalg.norm(l + v))
    width = 1000.0 * pitch * k_len / math.sqrt(material.ey)  # 1σ of the lobe in λ
    assert abs(peak - lam_target) <= width, (peak, lam_target, width)
    assert spectrum.max() > 0.0
