"""Float64 reference of the thin-film source (docs/physics.md §1).

A film of index ``n_film`` and thickness ``d`` (nm) on a substrate of index
``n_sub``, under air. Light meets it at cos θ1 = v·h (the facet's normal is the
half vector); inside the film cos θ2 follows from Snell. With real indices the
Fresnel amplitude coefficients a = r12, b = r23 are real and signed (their
sign is the interface's 0 or π phase shift), and Airy's sum of the multiply
reflected waves gives, per polarisation,

    R(φ) = (a² + b² + 2ab·cos φ) / (1 + a²b² + 2ab·cos φ),   φ = 4π·n_film·d·cos θ2 / λ

averaged over s and p (unpolarised light). Total internal reflection at
either interface gives R = 1. Each function mirrors the GLSL function of the
same name in glsl/lib/thin_film.glsl.

A conductor substrate (docs/physics.md §1.2) has a complex index ñ = n + ik,
so b = |b|·e^{iψ} is complex: its phase ψ adds to the film's, and the same sum
is exact with b → |b| and φ → φ + ψ. Where ``n_sub`` is complex, the functions
below take that branch; the lower interface then never reflects totally (an
evanescent wave in a lossless medium comes out as |b| = 1, R = 1, by itself).
"""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

from opaline.model import visible
from opaline.model.airy_band import airy_band, bin_damping
from opaline.model.color_space import radiance_floor
from opaline.model.microfacet import FloatArray, Values
from opaline.model.spectrum import RANGE_NM, rgb_weights, sample_wavelengths

# Per polarisation (s, p): one Fresnel amplitude coefficient each.
# (r23 is complex under a conductor.)
Amplitudes: TypeAlias = tuple[npt.NDArray[Any], npt.NDArray[Any]]
# Under the film: a dielectric's real index, or a conductor's n + ik per wavelength.
Substrate: TypeAlias = "float | npt.NDArray[np.complex128]"

FAST_TERMS = 3  # Fourier terms of the fast path; |ab|^4 < 1e-3 below grazing


def interfaces(
    cos1: npt.ArrayLike, n_film: float, n_sub: Substrate
) -> tuple[FloatArray, Amplitudes, Amplitudes, npt.NDArray[np.bool_]]:
    """(cos θ2, r12 s/p, r23 s/p, tir): Fresnel amplitudes at both interfaces (r23
    complex under a conductor)."""
    cos1 = np.clip(np.asarray(cos1, dtype=np.float64), 0.0, 1.0)
    # cos²θ2 = 1 - sin²θ1/n² written as (n² - 1 + cos²θ1)/n²: near grazing 1 - cos²θ1
    # rounds to 1 in fp32, which would turn a film of index 1 into total reflection.
    cos1_sq = cos1 * cos1
    cos2_sq = (n_film * n_film - 1.0 + cos1_sq) / (n_film * n_film)
    if np.iscomplexobj(n_sub):
        return _conductor_interfaces(cos1, cos2_sq, n_film, np.asarray(n_sub))
    cos3_sq = (n_sub * n_sub - 1.0 + cos1_sq) / (n_sub * n_sub)
    tir = (cos2_sq <= 0.0) | (cos3_sq <= 0.0)
    cos2 = np.sqrt(np.maximum(cos2_sq, 0.0))
    cos3 = np.sqrt(np.maximum(cos3_sq, 0.0))
    r12s = _ratio(cos1 - n_film * cos2, cos1 + n_film * cos2)
    r12p = _ratio(n_film * cos1 - cos2, n_film * cos1 + cos2)
    r23s = _ratio(n_film * cos2 - n_sub * cos3, n_film * cos2 + n_sub * cos3)
    r23p = _ratio(n_sub * cos2 - n_film * cos3, n_sub * cos2 + n_film * cos3)
    return cos2, (r12s, r12p), (r23s, r23p), tir


def _conductor_interfaces(
    cos1: FloatArray, cos2_sq: npt.NDArray[Any], n_film: float, n_sub: npt.NDArray[np.complex128]
) -> tuple[FloatArray, Amplitudes, Amplitudes, npt.NDArray[np.bool_]]:
    """``interfaces`` over ñ = n + ik: ñ·cos θ3 = √(ñ² - sin²θ1) on the principal branch,
    whose imaginary part is ≥ 0 (the wave decays into the metal for k > 0). Exactly
    grazing light is reflected whole, as the dielectric's test for total reflection
    has it (a = -1 there; over a lossless ñ = 1, b = 1 too and Airy's sum is 0/0)."""
    tir = (cos2_sq <= 0.0) | (cos1 <= 0.0)
    cos2 = np.sqrt(np.maximum(cos2_sq, 0.0))
    n_cos3 = np.sqrt(n_sub * n_sub - 1.0 + cos1 * cos1 + 0j)
    n_sq = n_sub * n_sub
    r12s = _ratio(cos1 - n_film * cos2, cos1 + n_film * cos2)
    r12p = _ratio(n_film * cos1 - cos2, n_film * cos1 + cos2)
    r23s = _ratio(n_film * cos2 - n_cos3, n_film * cos2 + n_cos3)
    r23p = _ratio(n_sq * cos2 - n_film * n_cos3, n_sq * cos2 + n_film * n_cos3)
    return cos2, (r12s, r12p), (r23s, r23p), tir


def _ratio(num: npt.NDArray[Any], den: npt.NDArray[Any]) -> npt.NDArray[Any]:
    return num / np.where(np.abs(den) > 1e-30, den, 1e-30)


def airy(a: FloatArray, b: npt.NDArray[Any], phase: FloatArray) -> FloatArray:
    """Reflectance of one polarisation: |a + b·e^{iφ}|² / |1 + ab·e^{iφ}|² (a real; b
    real, or complex: |b| with its phase added to φ)."""
    if np.iscomplexobj(b):
        phase = phase + np.angle(b)
        b = np.abs(b)
    ab = a * b
    c = np.cos(phase)
    # The numerator cancels to ~0 where a = -b (no interface): rounding may not go negative.
    num: FloatArray = np.maximum(a * a + b * b + 2.0 * ab * c, 0.0)
    den: FloatArray = np.maximum(1.0 + ab * ab + 2.0 * ab * c, 1e-30)
    return num / den


def film_reflectance(
    cos1: npt.ArrayLike, lam_nm: Values, d_nm: Values, n_film: float, n_sub: Substrate,
    bin_nm: float = 0.0,
) -> FloatArray:
    """Airy reflectance averaged over s and p at wavelength ``lam_nm`` (broadcasts); over a
    conductor with ``bin_nm`` > 0, averaged across a bin that wide (model/airy_band.py)."""
    cos2, (r12s, r12p), (r23s, r23p), tir = interfaces(cos1, n_film, n_sub)
    phase = 4.0 * np.pi * n_film * d_nm * cos2 / lam_nm
    if bin_nm > 0.0 and np.iscomplexobj(r23s):
        rho = bin_damping(phase, lam_nm, bin_nm)
        r = 0.5 * (airy_band(r12s, r23s, phase, rho) + airy_band(r12p, r23p, phase, rho))
    else:
        r = 0.5 * (airy(r12s, r23s, phase) + airy(r12p, r23p, phase))
    return np.where(tir, 1.0, r)


def film_rgb_spectral(
    cos1: npt.ArrayLike, d_nm: npt.ArrayLike, n_film: float, n_sub: Substrate, wavelengths: int
) -> FloatArray:
    """Σ_i w_i·R(λ_i): ``wavelengths`` bins over 380-780 nm, CIE 1931 to linear sRGB (a
    conductor's ``n_sub`` has one n + ik per bin, and its R is averaged across the bin)."""
    cos1 = np.asarray(cos1, dtype=np.float64)
    lam = sample_wavelengths(wavelengths)
    weights = rgb_weights(wavelengths)
    r = film_reflectance(cos1[..., None], lam, np.asarray(d_nm)[..., None], n_film, n_sub,
                         (RANGE_NM[1] - RANGE_NM[0]) / wavelengths)  # each bin's width
    rgb: FloatArray = radiance_floor(r @ weights)  # a channel below 0: the display's map
    return rgb


def film_rgb_fast(
    cos1: npt.ArrayLike, d_nm: npt.ArrayLike, n_film: float, n_sub: float
) -> FloatArray:
    """Belcour & Barla 2017's evaluation: R(φ) as a Fourier series in φ, each term
    integrated against the colour weights in closed form (``visible.sensitivity``).

    For real a, b: R = c0 + 2·Σ_m c_m·cos(mφ), c0 = (a² + b² - 2x²)/(1 - x²),
    c_m = -(1 - a²)(1 - b²)/(1 - x²)·(-x)^m with x = ab. The sign of (-x)^m is a
    phase shift of π per order where x > 0. The first FAST_TERMS terms are
    integrated exactly; the rest (which matter near grazing, where |x| nears 1
    and a thin film must still come out as its bare substrate) are summed as a
    geometric series per Gaussian with the damping of the first omitted term."""
    cos1 = np.asarray(cos1, dtype=np.float64)
    cos2, r12, r23, tir = interfaces(cos1, n_film, n_sub)
    opd_um = 2e-3 * n_film * np.asarray(d_nm, dtype=np.float64) * cos2
    total: Values = 0.0
    for a, b in zip(r12, r23, strict=True):
        x = a * b
        one_minus = np.maximum(1.0 - x * x, 1e-30)
        c0 = (a * a + b * b - 2.0 * x * x) / one_minus
        amp = -(1.0 - a * a) * (1.0 - b * b) / one_minus
        shift = np.where(x > 0.0, np.pi, 0.0)
        rgb = c0[..., None]
        for m in range(1, FAST_TERMS + 1):
            term = amp * np.abs(x) ** m
            rgb = rgb + 2.0 * term[..., None] * visible.sensitivity(m * opd_um, m * shift)
        rgb = rgb + 2.0 * amp[..., None] * film_tail(np.abs(x), opd_um, shift)
        total = total + 0.5 * rgb
    return radiance_floor(np.where(tir[..., None], 1.0, total))


def film_tail(x_abs: npt.ArrayLike, opd_um: npt.ArrayLike, shift: npt.ArrayLike) -> Values:
    """Σ_{m > M} |x|^m·∫ ŵ cos(m(2π·opd·ν + shift)) dν, each Gaussian at its centre:
    Re(z^(M+1)/(1 - z)) with z = |x|·e^{iθ}, damped as the term m = M + 1."""
    g = visible.sensitivity_gaussians()
    big_m = FAST_TERMS
    x = np.asarray(x_abs)[..., None]
    opd = np.asarray(opd_um)[..., None]
    total: Values = 0.0
    for k in range(g.shape[0]):
        weight, centre, sigma = g[k, :, 0], g[k, :, 1], g[k, :, 2]
        theta = 2.0 * np.pi * centre * opd + np.asarray(shift)[..., None]
        damp = np.exp(-2.0 * (np.pi * sigma * opd * (big_m + 1)) ** 2)
        num = x ** (big_m + 1) * np.cos((big_m + 1) * theta) - x ** (big_m + 2) * np.cos(big_m * theta)
        den = np.maximum(1.0 - 2.0 * x * np.cos(theta) + x * x, 1e-12)
        total = total + weight * damp * num / den
    return total


def film_rgb_fast_conductor(
    cos1: npt.ArrayLike, d_nm: npt.ArrayLike, n_film: float, n_sub: npt.NDArray[np.complex128]
) -> FloatArray:
    """``film_rgb_fast`` over a conductor with one n + ik per channel (``n_sub``, R G B, at
    the channels' wavelengths): each channel's series with |b| and the phase ψ of b,
    which shifts every term, cos(m(φ + ψ)), integrated against that channel's weight."""
    cos1 = np.asarray(cos1, dtype=np.float64)
    channels = []
    for c in range(3):
        cos2, r12, r23, tir = interfaces(cos1, n_film, np.asarray(n_sub[c], np.complex128))
        opd_um = 2e-3 * n_film * np.asarray(d_nm, dtype=np.float64) * cos2
        total: FloatArray = np.zeros(np.shape(cos2))
        for a, b in zip(r12, r23, strict=True):
            b_abs = np.abs(b)
            x = a * b_abs
            one_minus = np.maximum(1.0 - x * x, 1e-30)
            channel = (a * a + b_abs * b_abs - 2.0 * x * x) / one_minus
            amp = -(1.0 - a * a) * (1.0 - b_abs * b_abs) / one_minus
            shift = np.angle(b) + np.where(x > 0.0, np.pi, 0.0)
            for m in range(1, FAST_TERMS + 1):
                wave = np.asarray(visible.sensitivity(m * opd_um, m * shift))[..., c]
                channel = channel + 2.0 * amp * np.abs(x) ** m * wave
            channel = channel + 2.0 * amp * np.asarray(film_tail(np.abs(x), opd_um, shift))[..., c]
            total = total + 0.5 * channel
        channels.append(np.where(tir, 1.0, total))
    rgb: FloatArray = radiance_floor(np.stack(channels, axis=-1))
    return rgb


def film_base_rgb(cos1: npt.ArrayLike, n_sub: Substrate, wavelengths: int = 0) -> FloatArray:
    """The base without its film: the bare substrate's Fresnel reflectance from air (the
    lower interface under a film of index 1), s and p averaged, 1 exactly at grazing;
    white over a dielectric (each path's colour weights sum to 1), a metal's integrated
    as the film is (per wavelength, or per channel's n + ik)."""
    cos1 = np.clip(np.asarray(cos1, dtype=np.float64), 0.0, 1.0)
    if not np.iscomplexobj(n_sub):
        _, _, (rs, rp), tir = interfaces(cos1, 1.0, n_sub)
        bare = np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))
        return np.repeat(bare[..., None], 3, axis=-1)
    _, _, (rs, rp), tir = interfaces(cos1[..., None], 1.0, np.asarray(n_sub))
    bare = np.where(tir, 1.0, 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2))
    if wavelengths > 0:
        bare = bare @ rgb_weights(wavelengths)
    return radiance_floor(bare)


def film_layer_rgb(
    cos1: npt.ArrayLike, d_nm: npt.ArrayLike, n_film: float, n_sub: Substrate,
    weight: float = 1.0, wavelengths: int = 0,
) -> FloatArray:
    """KHR_materials_iridescence's layering: mix(base, film, weight) (iridescenceFactor)."""
    film = film_rgb(cos1, d_nm, n_film, n_sub, wavelengths)
    if weight >= 1.0:
        return film
    base = film_base_rgb(cos1, n_sub, wavelengths)
    mixed: FloatArray = base + weight * (film - base)
    return mixed


def film_rgb(
    cos1: npt.ArrayLike, d_nm: npt.ArrayLike, n_film: float, n_sub: Substrate,
    wavelengths: int = 0,
) -> FloatArray:
    if wavelengths > 0:
        return film_rgb_spectral(cos1, d_nm, n_film, n_sub, wavelengths)
    if np.iscomplexobj(n_sub):
        return film_rgb_fast_conductor(cos1, d_nm, n_film, np.asarray(n_sub))
    return film_rgb_fast(cos1, d_nm, n_film, float(n_sub))
