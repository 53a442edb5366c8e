"""An independent check of the float64 thin-film reflectance (model/thinfilm.py) against
colour-science's transfer-matrix method (colour.phenomena.interference.thin_film_tmm,
Byrnes 2016), to 1e-9 in reflectance, for s, p and their average.

Like with like: thin_film_tmm returns R per wavelength, angle, thickness and
polarisation [R_s, R_p]; Opaline's ``film_reflectance`` returns the unpolarised
average (s + p)/2 and ``airy(r12, r23, φ)`` one polarisation's Airy sum, so those two
are compared. Its p amplitudes have the opposite sign to Opaline's (Byrnes' eq. 6 vs
Born & Wolf's), at both interfaces at once, which leaves every reflectance as it is;
both take an absorbing index as n + ik with k > 0 (checked: the film's phase over a
metal would differ otherwise).

One real disagreement, which is colour-science's: its ``tmm.snell_law`` takes the real
part of each index and a real arcsin, so under an absorbing substrate (k > 0) at oblique
incidence it uses a real refraction angle from Re(ñ) instead of ñ·cos θ = √(ñ² - sin²θ)
(and answers NaN where Re(ñ) < sin θ, silver's n ≈ 0.05-0.2). Its bare-metal Fresnel at
60° for ñ = 2.9 + 3i is R_s 0.7067 against the textbook's 0.7236; over films on the
tabulated metals below, 0-84°, it departs from Opaline (and from the matrix) by up to
0.72. So a film on a metal is compared with
colour-science at normal incidence, where the angle does not enter, and, through the
conductor branch, with a lossless complex index at every angle; at oblique incidence
on a metal it is held against the characteristic (Abelès) matrix written out below,
an independent derivation (Macleod, Thin-Film Optical Filters, §2.2: admittances, not
Airy's sum of reflections). Measured: at most 3e-14 everywhere (dielectrics 2.7e-14,
metals at normal incidence 1.1e-14, the lossless conductor branch 7e-15, the matrix
1.8e-14).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from opaline.model import metals, thinfilm

colour_interference = pytest.importorskip("colour.phenomena.interference")

TOLERANCE = 1e-9
ANGLES = np.arange(0.0, 84.1, 6.0)  # degrees, 0 … 84
THICKNESSES = np.array([0.0, 1.0, 10.0, 75.0, 230.0, 480.0, 777.0, 1200.0])  # nm
LAMBDAS = np.array([380.0, 455.0, 530.0, 610.0, 700.0, 780.0])  # nm
# (film, substrate): film above and below the substrate, a free film (soap: air under),
# no film contrast at all, and the ends of both ranges.
DIELECTRICS = [(1.3, 1.5), (1.5, 1.33), (1.33, 1.0), (2.4, 1.5), (1.0, 1.0), (1.0, 4.0),
               (3.0, 1.0), (3.0, 4.0), (1.68, 1.53)]
METALS = ("gold", "silver", "copper", "aluminium", "titanium", "iron", "bismuth")


def opaline_s_p(cos1, lam, d, n_film, n_sub):
    """Opaline's per-polarisation Airy reflectance (the terms film_reflectance averages)."""
    cos2, r12, r23, tir = thinfilm.interfaces(cos1, n_film, n_sub)
    phase = 4.0 * np.pi * n_film * d * cos2 / lam
    return [np.where(tir, 1.0, thinfilm.airy(a, b, phase)) for a, b in zip(r12, r23, strict=True)]


def grid(n_film, n_sub, angles):
    """Opaline's R_s, R_p and average on the (wavelength, angle, thickness) grid; n_sub a
    number or one n + ik per wavelength."""
    cos1 = np.cos(np.radians(angles))[None, :, None]
    lam, d = LAMBDAS[:, None, None], THICKNESSES[None, None, :]
    sub = np.asarray(n_sub)[:, None, None] if np.ndim(n_sub) else n_sub
    rs, rp = opaline_s_p(cos1, lam, d, n_film, sub)
    average = thinfilm.film_reflectance(cos1, lam, d, n_film, sub)
    return np.stack([rs, rp, average], axis=-1)


def colour_grid(n_film, n_sub, angles):
    """thin_film_tmm's [R_s, R_p] and their average on the same grid."""
    n = np.array([np.ones_like(LAMBDAS), np.full_like(LAMBDAS, n_film),
                  np.broadcast_to(n_sub, LAMBDAS.shape)], dtype=np.result_type(n_sub, float))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its arcsin warns at grazing on a lossless substrate
        r, _ = colour_interference.thin_film_tmm(n, THICKNESSES, LAMBDAS, angles)
    return np.concatenate([r, r.mean(axis=-1, keepdims=True)], axis=-1)


@pytest.mark.parametrize(("n_film", "n_sub"), DIELECTRICS)
def test_dielectric_film_agrees_with_colour_science(n_film, n_sub):
    ours, theirs = grid(n_film, n_sub, ANGLES), colour_grid(n_film, n_sub, ANGLES)
    assert np.isfinite(theirs).all()
    assert np.abs(ours - theirs).max() < TOLERANCE


@pytest.mark.parametrize("metal", METALS)
@pytest.mark.parametrize("n_film", [1.0, 1.45, 2.6])
def test_film_on_a_metal_at_normal_incidence_agrees_with_colour_science(metal, n_film):
    nk = metals.metal_index(metal, LAMBDAS)
    ours, theirs = grid(n_film, nk, np.array([0.0])), colour_grid(n_film, nk, np.array([0.0]))
    assert np.abs(ours - theirs).max() < TOLERANCE


@pytest.mark.parametrize("n_sub", [1.0, 1.33, 2.5, 4.0])
def test_conductor_branch_with_a_lossless_index_agrees_at_every_angle(n_sub):
    """The conductor's code (complex ñ·cos θ3 on the principal branch) with k = 0, where
    colour-science's real Snell's law is exact."""
    index = np.complex128(n_sub)
    ours = grid(1.8, np.full(LAMBDAS.shape, index), ANGLES)
    assert np.abs(ours - colour_grid(1.8, index, ANGLES)).max() < TOLERANCE


def abeles(cos0, lam, d, n_film, n_sub):
    """R_s, R_p of one film by its characteristic matrix, in Macleod's convention (fields
    e^{i(ωt - kz)}, so an absorbing index is n - ik there: the conjugate of Opaline's)."""
    sin2 = 1.0 - cos0 * cos0
    films, subs = np.conj(n_film + 0j), np.conj(n_sub + 0j)
    out = []
    for p in (False, True):
        def admittance(n, p=p):
            n_cos = np.sqrt(n * n - sin2 + 0j)  # Im ≤ 0 for n - ik: the decaying root
            return n * n / n_cos if p else n_cos

        delta = 2.0 * np.pi * np.sqrt(films * films - sin2 + 0j) * d / lam
        eta0, eta1, eta2 = admittance(1.0 + 0j), admittance(films), admittance(subs)
        b = np.cos(delta) + 1j * np.sin(delta) * eta2 / eta1
        c = 1j * eta1 * np.sin(delta) + np.cos(delta) * eta2
        out.append(np.abs((eta0 * b - c) / (eta0 * b + c)) ** 2)
    return out


@pytest.mark.parametrize("metal", METALS)
@pytest.mark.parametrize("n_film", [1.0, 1.45, 2.6])
def test_film_on_a_metal_at_oblique_incidence_agrees_with_the_characteristic_matrix(
        metal, n_film):
    nk = metals.metal_index(metal, LAMBDAS)[:, None, None]
    cos1 = np.cos(np.radians(ANGLES))[None, :, None]
    lam, d = LAMBDAS[:, None, None], THICKNESSES[None, None, :]
    ours = opaline_s_p(cos1, lam, d, n_film, nk)
    matrix = abeles(cos1, lam, d, n_film, nk)
    for got, expected in zip(ours, matrix, strict=True):
        assert np.abs(got - expected).max() < TOLERANCE
    average = thinfilm.film_reflectance(cos1, lam, d, n_film, nk)
    assert np.abs(average - 0.5 * (matrix[0] + matrix[1])).max() < TOLERANCE
