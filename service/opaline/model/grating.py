"""Float64 reference of the grating source (docs/physics.md §2).

A 1-D reflection grating: grooves along the tangent t, grating vector along the
bitangent b, pitch d. Order m at wavelength λ leaves where the tangential
momentum matches, (l + v)·b = m·λ/d and (l + v)·t = 0. Its lobe is the
Ashikhmin-Shirley MDF at the direction of the shifted sum

    k_m = l + v - (m·λ/d)·b,        h_m = k_m / |k_m|

(for m = 0 the ordinary half vector), so every order has the roughness (ex, ey)
of the specular highlight. With dω_h/dω_v = (v·h_m)/|k_m|² (for m = 0 this is
the familiar 1/(4 v·h)) the order contributes

    ks · η_m(λ) · F(v·h_m) · D(h_m) · (v·h_m) / (|k_m|² · max(n·l, n·v)).

Efficiency: a sinusoidal groove of depth δ is a thin phase grating of phase
amplitude a = π·δ·(n·(l + v))/λ, whose orders carry η_m = J_m(a)² (Σ_m η_m = 1).
Each function mirrors the GLSL function of the same name in glsl/lib/grating.glsl.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, cast

import numpy as np
import numpy.typing as npt

from opaline.model import visible
from opaline.model.color_space import radiance_floor
from opaline.model.microfacet import (
    EPS_DENOM,
    FloatArray,
    Frame,
    Values,
    fresnel_schlick,
    mdf_ashikhmin,
)
from opaline.model.spectrum import RANGE_NM, rgb_weights, sample_wavelengths

if TYPE_CHECKING:
    from opaline.model.params import Material

BESSEL_TERMS = 24  # series terms: below 1e-9 of the sum for a ≤ 7 (depth ≤ 400 nm)
SHADER_BESSEL_TERMS = 16  # the shader's most: truncation below 1e-9 for a ≤ 7
# J_m's series is cut where its first term left out is under this: 1e-9 where the shading
# is checked against its float64 twin to 1e-6. A map read of the orders
# (glsl/lib/environment_grating.glsl) is a box over the map, within FLIP 0.03-0.07 of the
# reads converged (bench/grating_environment.py): there 1e-6, two terms fewer at the CD's
# 150 nm, whose Bessel series were ~60 % of what the studio adds to its key light's time.
SERIES_TOLERANCE = 1e-9
READS_SERIES_TOLERANCE = 1e-6
EPS_K2 = 1e-12


def bessel_j(m: int, x: npt.ArrayLike) -> FloatArray:
    """J_m(x) from its power series Σ_k (-1)^k (x/2)^(2k+m) / (k!(k+m)!), as the shader does."""
    x = np.asarray(x, dtype=np.float64)
    half = 0.5 * x
    term = half**m / math.factorial(m)
    total = term
    q = -half * half
    for k in range(1, BESSEL_TERMS):
        term = term * q / (k * (k + m))
        total = total + term
    return total


def bessel_terms(depth_nm: float, tolerance: float = SERIES_TOLERANCE) -> int:
    """The terms the shader sums J_m's series to (its BESSEL_TERMS define): the fewest
    whose first left out, (a/2)^2k/k!², is under ``tolerance`` at the largest a this depth
    reaches, π·depth·2/380 nm (n·(l+v) ≤ 2, λ ≥ 380 nm); 16 at the deepest grooves
    (a ≤ 6.6). A shallow groove's series is short: 9 terms at the CD's 150 nm, about half
    the cost."""
    half_x = math.pi * depth_nm * 2.0 / 380.0 / 2.0
    term, k = 1.0, 0
    while term >= tolerance and k < SHADER_BESSEL_TERMS:
        k += 1
        term *= half_x * half_x / (k * k)
    return max(k, 2)


def efficiency(m: int, lam_nm: Values, depth_nm: float, kn: FloatArray) -> FloatArray:
    """η_m = J_|m|(a)², a = π·depth·(n·(l+v))/λ."""
    return bessel_j(abs(m), np.pi * depth_nm * kn / lam_nm) ** 2


def _local(frame: Frame, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    t, b, n = frame
    return np.sum(x * t, axis=-1), np.sum(x * b, axis=-1), np.sum(x * n, axis=-1)


def order_lobe(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, m: int, lam_nm: Values
) -> FloatArray:
    """One order's lobe at one wavelength, without ks and η: F·D(h_m)·(v·h_m)/(|k_m|²·max(n·l, n·v))."""
    kt, kb, kn = _local(frame, l + v)
    vt, vb, vn = _local(frame, v)
    ln = _local(frame, l)[2]
    kb = kb - m * lam_nm / (1000.0 * material.grating_pitch)
    k2 = np.maximum(kt * kt + kb * kb + kn * kn, EPS_K2)
    k_len = np.sqrt(k2)
    d = mdf_ashikhmin(kt / k_len, kb / k_len, kn / k_len, material.ex, material.ey)
    vh = (vt * kt + vb * kb + vn * kn) / k_len
    f = fresnel_schlick(material.f0, vh)
    lobe: FloatArray = (f * d * np.maximum(vh, 0.0)
                        / (k2 * np.maximum(np.maximum(ln, vn), EPS_DENOM)))
    return lobe


def order_term(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, m: int, lam_nm: Values
) -> FloatArray:
    """η_m(λ) times the order's lobe."""
    kn = np.maximum(_local(frame, l + v)[2], 0.0)
    eta = efficiency(m, lam_nm, material.grating_depth, kn)
    return eta * order_lobe(material, frame, l, v, m, lam_nm)


def grating_spectral(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, wavelengths: int
) -> FloatArray:
    """Σ_i w_i Σ_{|m| ≤ M} term(m, λ_i): per-wavelength, integrated to linear sRGB."""
    lam = sample_wavelengths(wavelengths)
    weights = rgb_weights(wavelengths)
    orders = material.grating_orders
    total: Values = 0.0
    for lam_i, w in zip(lam, weights, strict=True):
        # Orders -1, 0 and 1 at least: never the empty sum's 0.
        s = cast(FloatArray, sum(order_term(material, frame, l, v, m, lam_i)
                                 for m in range(-orders, orders + 1)))
        total = total + s[..., None] * w
    result = radiance_floor(total)  # a channel below 0 goes to the display's gamut map
    return result


def channel_wavelengths() -> np.ndarray:
    """Centroid of each channel's weight (nm): where the fast path evaluates η_0."""
    grid, table = visible.density_table()
    centroid: np.ndarray = np.sum(grid[:, None] * table, axis=0) / np.sum(table, axis=0)
    return centroid


def grating_fast(material: Material, frame: Frame, l: FloatArray, v: FloatArray) -> FloatArray:
    """Each order straight at its wavelength λ_m = d·(l+v)·b/m (Stam 1999's idea).

    The lobe's extent in λ is integrated in closed form under a Gaussian
    approximation of the A-S lobe across the grooves, exp(-ey·h_b²/2):
    ∫ D dλ ≈ D(h at k_b = 0)·(d/|m|)·|k_0|·√(2π/ey), the colour weight averaged over the
    box of the same variance, λ ± √3·(d/|m|)·|k_0|/√ey. A broad lobe's orders so blend
    toward white as the spectral path's do, where a point read of the weight kept them
    pure spectral colours."""
    kt, kb, kn = _local(frame, l + v)
    vt, _, vn = _local(frame, v)
    ln = _local(frame, l)[2]
    pitch_nm = 1000.0 * material.grating_pitch
    k0_sq = np.maximum(kt * kt + kn * kn, EPS_K2)
    k0 = np.sqrt(k0_sq)
    d0 = mdf_ashikhmin(kt / k0, 0.0 * kt, kn / k0, material.ex, material.ey)
    vh0 = (vt * kt + vn * kn) / k0
    base = fresnel_schlick(material.f0, vh0) * d0 * np.maximum(vh0, 0.0)
    base = base / (k0_sq * np.maximum(np.maximum(ln, vn), EPS_DENOM))
    kn_pos = np.maximum(kn, 0.0)
    total: Values = 0.0
    for m in range(1, material.grating_orders + 1):
        for sign in (1, -1):
            lam = sign * pitch_nm * kb / m
            spread = (pitch_nm / m) * k0 * math.sqrt(2.0 * math.pi / max(material.ey, 1.0))
            # The colour over the lobe's extent in λ: the box of the Gaussian's variance.
            half = math.sqrt(3.0) * (pitch_nm / m) * k0 / math.sqrt(max(material.ey, 1.0))
            density = visible.filtered_density(lam, half)
            # η held in the visible range: outside it the colour is 0 (or the lobe's
            # reach into it), and a tiny λ would overflow the Bessel series.
            eta = efficiency(m, np.clip(lam, *RANGE_NM), material.grating_depth, kn_pos)
            total = total + density * (spread * eta * base)[..., None]
    zero = order_lobe(material, frame, l, v, 0, 550.0)  # m = 0: k does not depend on λ
    eta0 = np.stack(
        [efficiency(0, lam_c, material.grating_depth, kn_pos) for lam_c in channel_wavelengths()],
        axis=-1,
    )
    result = radiance_floor(total + zero[..., None] * eta0)
    return result
