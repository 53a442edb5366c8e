"""Airy's sum over a conductor averaged across a wavelength's bin: the float64 twin of
``film_airy_band`` in glsl/lib/thin_film_conductor.glsl.

The spectral path reads a film at a few wavelengths, each standing for a bin of
(780 − 380)/N nm. Across a bin the film's phase φ = 2π·opd/λ moves by
Δφ = φ·Δλ/λ, which for a micron-thick film on a metal is a whole cycle or more: read at
the bin's centre, 16 or 32 wavelengths drew the fringes as false colour rings where many
wavelengths give grey (a review found it on `tempered-steel` at 2000 nm). So each
wavelength reads R averaged over its bin's phases.

Per polarisation, with a real (the film's top) and b complex (the metal below),
R(z) = |a + b·z|²/|1 + ab·z|² for z = e^{iφ} is a Fourier series in φ whose m-th term
is C_m·z^m with, for q = −ab and β = (1 − a²)·b,

    C_0 = a² + |β|²/(1 − |q|²),   C_m = K·q^(m−1),   K = a·β + |β|²·q/(1 − |q|²),

so damping the m-th term by ρ^m (the Poisson kernel, an average over φ) sums in
closed form: R_ρ = C_0 + 2·Re(K·w/(1 − q·w)), w = ρ·z. ρ = 1 is Airy's value itself;
ρ = 0 is the incoherent sum |a|² + (1 − a²)²|b|²/(1 − a²|b|²), the limit of a thick
film.

ρ = exp(−(Δφ/π)⁴): samples Δφ apart resolve the terms with m·Δφ < π, and this keeps
them (ρ = 0.94 at Δφ = π/2) and removes the first term where it would alias (ρ = 0.37
at Δφ = π, 1e-7 at 2π). ρ = exp(−Δφ²/24), which damps the first term as a box of width
Δφ does, was measured first: it also damped what the samples resolve, and thin films,
whose midpoint reads are second-order accurate already, came out worse than unfiltered
(against 2048 wavelengths, docs/physics.md §1.2).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from opaline.model.microfacet import FloatArray


def bin_damping(phase: npt.ArrayLike, lam_nm: npt.ArrayLike, bin_nm: float) -> FloatArray:
    """ρ for a phase ``phase`` (radians) at ``lam_nm`` read for a bin ``bin_nm`` wide."""
    spread = np.asarray(phase, dtype=np.float64) * bin_nm / np.asarray(lam_nm, dtype=np.float64)
    rho: FloatArray = np.exp(-((spread / np.pi) ** 4))
    return rho


def airy_band(a: FloatArray, b: npt.NDArray[Any], phase: FloatArray,
              rho: npt.ArrayLike) -> FloatArray:
    """One polarisation's R averaged over phases about ``phase`` by a Poisson kernel of
    radius ``rho`` (a real, b complex)."""
    beta = (1.0 - a * a) * b
    q = -a * b
    beta_sq = np.abs(beta) ** 2
    inverse = 1.0 / np.maximum(1.0 - np.abs(q) ** 2, 1e-30)
    c0 = a * a + beta_sq * inverse
    k = a * beta + beta_sq * inverse * q
    w = np.asarray(rho) * np.exp(1j * np.asarray(phase))
    # 1 − q·w vanishes only exactly at grazing (a = −1, |b| = 1), where the caller takes 1:
    # floored as the shader's complex division floors it, so no 0/0 is formed.
    den = 1.0 - q * w
    term = k * w * np.conj(den) / np.maximum(np.abs(den) ** 2, 1e-30)
    value: FloatArray = np.maximum(c0 + 2.0 * np.real(term), 0.0)
    return value
