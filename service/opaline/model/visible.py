"""The visible spectrum as continuous colour weights, for the fast RGB paths.

The spectral paths sum per-wavelength values with ``spectrum.rgb_weights``: CIE
1931 2° colour matching functions under D65 taken to linear sRGB, normalised so a
flat spectrum gives R = G = B. The fast paths need the same weights as
*densities* (per nm, or per µm⁻¹ of wavenumber) so that an integral can be done
in closed form:

- ``density_table``: ŵ_c(λ) per nm on a 5 nm grid, each channel integrating to
  1 over 380-780 nm; the grating's fast path reads it at the wavelength an
  order diffracts toward the viewer (Stam 1999's idea).
- ``SENSITIVITY``: ŵ_c(ν) over wavenumber ν = 1/λ (µm⁻¹) as four Gaussians per
  channel, fitted once (bench/fit_sensitivity.py, worst error 1.1-2.1 % of each
  peak; three reached 3.4 % under D65, whose spectrum has a dip at 590 nm) by the
  method of Belcour & Barla 2017: the Fourier transform of a Gaussian is a
  Gaussian, so ∫ ŵ_c(ν) cos(2π·OPD·ν + s) dν has a closed form, which is what
  lets a thin film's spectral integral be evaluated without wavelengths. Fitted
  to our own sRGB weights under D65 (not XYZ), so the fast path converges
  to the spectral one where the film's colour is flat.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import numpy.typing as npt

from opaline.model.microfacet import Values
from opaline.model.spectrum import RANGE_NM, XYZ_TO_SRGB, white_xyz

TABLE_STEP_NM = 5.0
TABLE_SIZE = int((RANGE_NM[1] - RANGE_NM[0]) / TABLE_STEP_NM) + 1  # 81 entries, both ends

# (amplitude, centre µm⁻¹, sigma µm⁻¹) per Gaussian, four per channel R, G, B: fitted by
# bench/fit_sensitivity.py.
SENSITIVITY_GAUSSIANS = 4
_FIT = np.array(
    [
        [
            [-2.64147, 1.87996, 0.12551],
            [0.47325, 2.27150, 0.06847],
            [8.06440, 1.64967, 0.07239],
            [1.89804, 1.77529, 0.05809],
        ],
        [
            [-1.85212, 1.65045, 0.08108],
            [4.39347, 1.81480, 0.13017],
            [-0.46885, 2.25018, 0.08173],
            [0.39741, 1.89572, 0.04441],
        ],
        [
            [0.41451, 2.01612, 0.06438],
            [-0.50980, 1.81318, 0.11088],
            [3.83310, 2.22823, 0.09604],
            [1.00996, 2.13971, 0.05945],
        ],
    ]
)


def _fine_density() -> tuple[np.ndarray, np.ndarray]:
    lam = np.arange(RANGE_NM[0], RANGE_NM[1] + 0.5, 1.0)
    rgb = white_xyz(lam) @ XYZ_TO_SRGB.T
    return lam, rgb / np.trapezoid(rgb, lam, axis=0)


@lru_cache(maxsize=1)
def density_table() -> tuple[np.ndarray, np.ndarray]:
    """(λ in nm, ŵ per nm as (TABLE_SIZE, 3)): each channel integrates to 1."""
    lam, dens = _fine_density()
    grid = RANGE_NM[0] + TABLE_STEP_NM * np.arange(TABLE_SIZE)
    table = np.stack([np.interp(grid, lam, dens[:, c]) for c in range(3)], axis=1)
    table /= np.trapezoid(table, grid, axis=0)
    table.setflags(write=False)
    return grid, table


@lru_cache(maxsize=1)
def cumulative_table() -> np.ndarray:
    """∫ ŵ(λ) dλ from 380 nm to each point of ``density_table``'s grid, (TABLE_SIZE, 3):
    exact for its piecewise-linear density, 0 at 380 nm and 1 at 780 nm."""
    grid, table = density_table()
    steps = 0.5 * (table[1:] + table[:-1]) * np.diff(grid)[:, None]
    cumulative = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    cumulative.setflags(write=False)
    return cumulative


# The cumulative table as the shader reads it: each point's value and the step to the next
# in one 32-bit word a channel, 16 bits each (fixed point over these ranges; the table
# spans -0.41 … 1.11, its steps -0.045 … 0.106). A read is then one gather from the
# uniform array, not two: on llvmpipe the gathers are most of what a grating's orders
# cost under an environment (docs/speed.md).
PACKED_VALUE = (-0.5, 1.5)
PACKED_STEP = (-0.125, 0.125)
_PACKED_LEVELS = 65535.0


def _quantised(values: np.ndarray, span: tuple[float, float]) -> np.ndarray:
    scale = (span[1] - span[0]) / _PACKED_LEVELS
    return np.round((values - span[0]) / scale).astype(np.uint32)


def _dequantised(levels: np.ndarray, span: tuple[float, float]) -> np.ndarray:
    return levels.astype(np.float64) * ((span[1] - span[0]) / _PACKED_LEVELS) + span[0]


@lru_cache(maxsize=1)
def packed_cumulative() -> np.ndarray:
    """(TABLE_SIZE, 3) uint32: point i's value (high 16 bits) and the step from its
    quantised value to point i + 1's (low 16 bits), so the line through a segment meets
    the next point's quantised value to within a step level (4e-6). Read by
    ``visible_cumulative`` in glsl/lib/grating.glsl; the last point's step is 0."""
    value = _quantised(cumulative_table(), PACKED_VALUE)
    nodes = _dequantised(value, PACKED_VALUE)
    steps = np.concatenate([np.diff(nodes, axis=0), np.zeros((1, 3))])
    packed: np.ndarray = (value << np.uint32(16)) | _quantised(steps, PACKED_STEP)
    packed.setflags(write=False)
    return packed


def packed_cumulative_uniform() -> list[tuple[int, int, int]]:
    """``packed_cumulative`` as the shader's ``u_visible_cumulative`` takes it."""
    return [(int(r), int(g), int(b)) for r, g, b in packed_cumulative()]


def cumulative_at(lam_nm: npt.ArrayLike) -> np.ndarray:
    """The cumulative table as packed (``packed_cumulative``): a point's value plus the
    fraction of its step, held beyond the ends; within 3.1e-5 of ``cumulative_table``
    linear between its points.

    Mirrors ``visible_cumulative`` in glsl/lib/grating.glsl."""
    grid, _ = density_table()
    lam = np.asarray(lam_nm, dtype=np.float64)
    packed = packed_cumulative()
    x = np.clip((lam - RANGE_NM[0]) / TABLE_STEP_NM, 0.0, TABLE_SIZE - 1.0)
    i = np.minimum(np.floor(x).astype(int), TABLE_SIZE - 2)
    value = _dequantised(packed[i] >> np.uint32(16), PACKED_VALUE)
    step = _dequantised(packed[i] & np.uint32(0xFFFF), PACKED_STEP)
    result: np.ndarray = value + (x - i)[..., None] * step
    return result


def filtered_density(lam_nm: npt.ArrayLike, half_nm: npt.ArrayLike) -> np.ndarray:
    """ŵ(λ) averaged over λ ± half (a lobe's extent in wavelength), from the cumulative
    table; the plain density where half is under half a table step.

    Mirrors ``visible_filtered`` in glsl/lib/grating.glsl."""
    lam = np.asarray(lam_nm, dtype=np.float64)
    half = np.broadcast_to(np.asarray(half_nm, dtype=np.float64), lam.shape)
    wide = half >= 0.5 * TABLE_STEP_NM
    safe = np.where(wide, half, 1.0)[..., None]
    average = (cumulative_at(lam + np.where(wide, half, 1.0))
               - cumulative_at(lam - np.where(wide, half, 1.0))) / (2.0 * safe)
    return np.where(wide[..., None], average, density_at(lam))


def density_at(lam_nm: npt.ArrayLike) -> np.ndarray:
    """ŵ(λ) per nm by linear interpolation in the table; 0 outside the visible range.

    Mirrors ``visible_density`` in glsl/lib/grating.glsl."""
    grid, table = density_table()
    lam = np.asarray(lam_nm, dtype=np.float64)
    x = (lam - RANGE_NM[0]) / TABLE_STEP_NM
    inside = (x >= 0.0) & (x <= TABLE_SIZE - 1)
    x = np.clip(x, 0.0, TABLE_SIZE - 1.0)
    i = np.minimum(np.floor(x).astype(int), TABLE_SIZE - 2)
    f = (x - i)[..., None]
    value = table[i] * (1.0 - f) + table[i + 1] * f
    return np.where(inside[..., None], value, 0.0)


@lru_cache(maxsize=1)
def sensitivity_gaussians() -> np.ndarray:
    """(3 Gaussians, 3 channels, 3 values): amplitude·σ·√(2π) (the Gaussian's integral),
    centre and σ, amplitudes scaled so each channel integrates to exactly 1 (white)."""
    fit = _FIT.copy()
    integral = fit[..., 0] * fit[..., 2] * np.sqrt(2.0 * np.pi)  # (channel, k)
    integral /= integral.sum(axis=1, keepdims=True)
    out = np.stack([integral, fit[..., 1], fit[..., 2]], axis=-1)  # (channel, k, 3)
    out = np.ascontiguousarray(out.transpose(1, 0, 2))  # (k, channel, 3)
    out.setflags(write=False)
    return out


def sensitivity(opd_um: npt.ArrayLike, shift: npt.ArrayLike) -> Values:
    """∫ ŵ_c(ν) cos(2π·opd·ν + shift) dν per channel, in closed form from the Gaussians.

    Mirrors ``film_sensitivity`` in glsl/lib/thin_film.glsl. ``opd_um``: optical path
    difference in µm; the result has a trailing axis of 3 (R, G, B)."""
    g = sensitivity_gaussians()
    opd = np.asarray(opd_um, dtype=np.float64)[..., None]
    shift = np.asarray(shift, dtype=np.float64)[..., None]
    total: Values = 0.0
    for k in range(g.shape[0]):
        weight, centre, sigma = g[k, :, 0], g[k, :, 1], g[k, :, 2]
        damp = np.exp(-2.0 * (np.pi * sigma * opd) ** 2)
        total = total + weight * np.cos(2.0 * np.pi * centre * opd + shift) * damp
    return total
