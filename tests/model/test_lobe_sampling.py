"""The lobe samplers of environment light (model/lobe_sampling.py, the float64 twins of
glsl/lib/lobe_sampling.glsl) draw what their densities say: each density integrates to
1 over the hemisphere (quadrature), and a histogram of samples matches it (χ²), for
Ashikhmin-Shirley at exponents 0 … 1e6 (isotropic and anisotropic), the projected
disc, and the rotation source's three-lobe mixture at θ in ±2π."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from lobe_quadrature import binned, cell_masses, phi_grid, w_grid
from opaline.model import lobe_sampling as ls
from opaline.model.microfacet import mdf_ashikhmin

TWO_PI = 2.0 * math.pi
EXPONENTS = {
    "ex=ey=0": (0.0, 0.0), "ex=ey=1e-6": (1e-6, 1e-6), "ex=ey=10": (10.0, 10.0),
    "ex=100,ey=10": (100.0, 10.0), "ex=10,ey=1000": (10.0, 1000.0),
    "ex=ey=1e6": (1e6, 1e6), "ex=0,ey=1e6": (0.0, 1e6), "ex=1e6,ey=1": (1e6, 1.0),
    "ex=1e6,ey=0": (1e6, 0.0),
}
MIXTURES = {
    "ex=100,ey=10,theta=0.3,-1": (100.0, 10.0, (0.0, 0.3, -1.0)),
    "ex=100,ey=10,theta=2pi,-2pi": (100.0, 10.0, (0.0, TWO_PI, -TWO_PI)),
    "ex=1e6,ey=1,theta=pi/2,1e-6": (1e6, 1.0, (0.0, math.pi / 2, 1e-6)),
    "ex=ey=1e3,theta=-3pi/2,pi": (1e3, 1e3, (0.0, -1.5 * math.pi, math.pi)),
}
SAMPLES = 200_000
# A correct sampler fails the χ² test with this probability (one fixed seed per case).
P_MIN = 1e-4


def ashikhmin_density(ex: float, ey: float):
    return lambda h: mdf_ashikhmin(h[..., 0], h[..., 1], h[..., 2], ex, ey)


def mixture_axes(thetas) -> tuple[float, ...]:
    # Each channel's lobe is eq. 1's turned by -θc: its principal axes are at -θc + kπ/2.
    return tuple(-t for t in thetas)


def total(density, axes=(0.0,)) -> float:
    return float(cell_masses(density, phi_grid(axes), w_grid()).sum())


@pytest.mark.parametrize("ex,ey", EXPONENTS.values(), ids=EXPONENTS.keys())
def test_ashikhmin_density_integrates_to_one(ex, ey):
    assert total(ashikhmin_density(ex, ey)) == pytest.approx(1.0, abs=1e-3)


def test_disc_density_integrates_to_one():
    assert total(lambda h: h[..., 2] / math.pi) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("ex,ey,thetas", MIXTURES.values(), ids=MIXTURES.keys())
def test_mixture_density_integrates_to_one(ex, ey, thetas):
    density = lambda h: ls.mixture_density(h, ex, ey, thetas)  # noqa: E731
    assert total(density, mixture_axes(thetas)) == pytest.approx(1.0, abs=1e-3)


def test_quadrature_sees_a_wrong_density():
    """The quadrature is fine enough to tell a density off by 1 % at the narrowest lobe."""
    wrong = lambda h: 1.01 * ashikhmin_density(1e6, 0.0)(h)  # noqa: E731
    assert abs(total(wrong) - 1.0) > 5e-3


def chi_square(h: np.ndarray, density, emax: float, axes) -> float:
    """p-value of the samples' (φ, 1 - hz) histogram against the density's bin masses;
    bins expecting fewer than 5 samples are pooled into one."""
    phi = np.mod(np.arctan2(h[:, 1], h[:, 0]), TWO_PI)
    w = 1.0 - h[:, 2]
    phi_edges = np.linspace(0.0, TWO_PI, 17)
    w_edges = np.unique(np.concatenate([[0.0], np.geomspace(0.02 / (emax + 1.0), 1.0, 12)]))
    expected = SAMPLES * binned(density, phi_edges, w_edges, axes)
    observed, _, _ = np.histogram2d(phi, w, bins=(phi_edges, w_edges))
    small = expected < 5.0
    e = np.append(expected[~small], expected[small].sum())
    o = np.append(observed[~small], observed[small].sum())
    e, o = e[e > 0], o[e > 0]
    assert o.sum() == SAMPLES
    statistic = float(((o - e) ** 2 / e).sum())
    return float(stats.chi2.sf(statistic, len(e) - 1))


def uniforms(seed: int, dims: int) -> np.ndarray:
    return np.random.default_rng(seed).random((SAMPLES, dims))


@pytest.mark.parametrize("ex,ey", EXPONENTS.values(), ids=EXPONENTS.keys())
def test_ashikhmin_samples_follow_their_density(ex, ey):
    h, pdf = ls.sample_ashikhmin(uniforms(1, 2), ex, ey)
    assert np.all(np.isfinite(h)) and np.all(h[:, 2] >= 0.0) and np.all(pdf > 0.0)
    assert np.allclose(np.linalg.norm(h, axis=1), 1.0, atol=1e-12)
    assert chi_square(h, ashikhmin_density(ex, ey), max(ex, ey), (0.0,)) > P_MIN


def test_disc_samples_follow_their_density():
    h, pdf = ls.sample_projected_disc(uniforms(2, 2))
    assert np.allclose(pdf, h[:, 2] / math.pi)
    assert chi_square(h, lambda d: d[..., 2] / math.pi, 0.0, (0.0,)) > P_MIN


@pytest.mark.parametrize("ex,ey,thetas", MIXTURES.values(), ids=MIXTURES.keys())
def test_mixture_samples_follow_their_density(ex, ey, thetas):
    h, pdf = ls.rotated_mixture(uniforms(3, 3), ex, ey, thetas)
    density = lambda d: ls.mixture_density(d, ex, ey, thetas)  # noqa: E731
    assert np.allclose(pdf, density(h))
    assert chi_square(h, density, max(ex, ey), mixture_axes(thetas)) > P_MIN


def test_histogram_sees_a_wrong_sampler():
    """The χ² test catches a sampler whose lobe is 5 % too wide (exponent off by 10 %)."""
    h, _ = ls.sample_ashikhmin(uniforms(1, 2), 90.0, 9.0)
    assert chi_square(h, ashikhmin_density(100.0, 10.0), 100.0, (0.0,)) < 1e-6
