"""The multi-peak lobe under an environment, float64 twin of its part of
``glsl/lib/environment_lobes.glsl`` (docs/design.md §4.5).

Eqs. 3-4 split as D(λ, h) = ½·hz + ½·hz·band(λ, h):

* the **envelope** ½·hz is the same at every wavelength and spans the hemisphere. Its
  integral against the map is its albedo A(n·v) (closed form below) times the map's
  mean radiance about a direction d between n and the mirror direction: the map's
  irradiance E(d)/π, from the nine coefficients the diffuse term already has;
* the **bands** carry the colour. Lobe samples read them, each band box-filtered over
  the share of the projected disc a sample stands for (``band_cell``). When that filter
  leaves them under ``BAND_FLOOR`` of the envelope everywhere on the lobe, no sample is
  drawn (``bands_resolved``): at one sample a pixel the presets' bands (mu_f·√min(α, β)
  ≈ 9) average to grey, as the converged integral over a broad light does.

Measured against the brute-force reference (bench/environment_accuracy.py, 128²), the
sphere preset under the studio's soft boxes went from FLIP 0.074 with 16 median-cut
lights (5.7× the key light's time) to 0.056 at 0.7× the key light's time.

The floor holds per wavelength; the colour matching weights, some negative, can sum the
dropped remainders of a channel to a little more than 5 % of its envelope.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import numpy.typing as npt

from opaline.model.reference import TWO_PI, sinc_half

FloatArray = npt.NDArray[np.float64]
# Below this the filtered bands are dropped: at most this share of the envelope's D.
BAND_FLOOR = 0.05
# band_mean's quadrature: exact to ~1e-10 up to this many cycles across the disc, with
# this many Gauss-Legendre nodes in ρ (and half as many angles over a quadrant).
MEAN_CYCLES = 8.0
MEAN_GRID = 64
# The direction the envelope's radiance is read about: n + WEIGHT·r, normalised (r the
# mirror direction). Measured against the brute-force reference (studio and sky, sphere
# and cd-rom presets) over 0, 0.25, 0.35, 0.5, 0.7 and 1: least FLIP at 0.35-0.5.
MIRROR_WEIGHT = 0.5
# Schlick's (1 − v·h)⁵ term of the envelope's albedo: a degree-6 fit in 1 − n·v to a
# quadrature of 2.25M points (within 7e-4 of it, against an albedo of 0.39-0.79).
SCHLICK_FIT = (1.42818824e+00, -3.31018136e+00, 3.11136970e+00, -1.31620555e+00,
               2.67333428e-01, -1.74354895e-02, 1.92833728e-04)


def albedo(nv: npt.ArrayLike, f0: float = 1.0) -> FloatArray:
    """∫ ½·hz·F(v·h)/(4·v·h·max(n·l, n·v))·n·l dω over the upper hemisphere: (π/8)·(2 − n·v)
    without Fresnel; with Schlick's F, f0 times that plus (1 − f0) times the fit."""
    cosine = np.clip(np.asarray(nv, dtype=np.float64), 0.0, 1.0)
    plain: FloatArray = np.pi / 8.0 * (2.0 - cosine)
    if f0 >= 1.0:
        return plain
    schlick = np.polyval(np.asarray(SCHLICK_FIT), 1.0 - cosine).astype(np.float64)
    result: FloatArray = f0 * plain + (1.0 - f0) * schlick
    return result


def dominant(n: FloatArray, v: FloatArray) -> FloatArray:
    """The envelope's direction: n + MIRROR_WEIGHT·r, normalised, r = 2(n·v)n − v."""
    r = 2.0 * (n * v).sum(-1, keepdims=True) * n - v
    d = n + MIRROR_WEIGHT * r
    result: FloatArray = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return result


def band_cell(hx: FloatArray, hy: FloatArray, mu_f: float, alpha: float, beta: float,
              cell: float) -> FloatArray:
    """cos(2π·mu_f·r) box-filtered over a square of side ``cell`` in the projected disc:
    the phase taken as linear across it, its slope in h for the pixel filter's screen
    derivatives (reference.mdf_multipeak_filtered)."""
    r = np.sqrt(alpha * hx * hx + beta * hy * hy)
    scale = mu_f / np.maximum(r, 1e-6)
    box = TWO_PI * cell
    result: FloatArray = (np.cos(TWO_PI * mu_f * r)
                          * sinc_half(box * np.abs(scale * alpha * hx))
                          * sinc_half(box * np.abs(scale * beta * hy)))
    return result


def cell_side(per_wavelength: int) -> float:
    """The side of the disc's share (area π/N) one of N samples of a wavelength stands for."""
    return math.sqrt(math.pi / per_wavelength)


@functools.cache
def _mean_grid() -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """band_mean's nodes: ρ, its weights, and hx, hy (ρ by angle); made once (4 ms)."""
    nodes, weights = np.polynomial.legendre.leggauss(MEAN_GRID)
    rho = 0.5 * (nodes + 1.0)
    angle = (np.arange(MEAN_GRID // 2) + 0.5) * (math.pi / MEAN_GRID)
    return rho, weights, rho[:, None] * np.cos(angle), rho[:, None] * np.sin(angle)


@functools.lru_cache(maxsize=256)  # a quadrature (~2 ms) per material and cell, not per render
def band_mean(mu_f: float, alpha: float, beta: float, cell: float = 0.0) -> float:
    """The band's mean over the projected disc (where its samples are drawn), filtered
    as the samples read it (``band_cell`` over ``cell``), which the envelope carries so
    that the samples carry only band − mean. Any constant keeps the split exact; this
    one leaves the samples nothing where the band is nearly constant (mu_f near 0, or
    α = β = 0: band 1, D = hz), where sampling the whole of it drew colour noise over a
    smooth lobe, and a remainder of mean 0 elsewhere (the filter over a wide cell takes
    the bands' mean with them: at mu_f 0.5 the unfiltered mean, −0.56, left the samples
    carrying +0.56 and their noise). By quadrature up to MEAN_CYCLES cycles
    across the disc, faded to 0 over the next MEAN_CYCLES, where it is within a few
    hundredths of 0 and the bands' own sampling carries them."""
    cycles = mu_f * math.sqrt(max(alpha, beta, 0.0))
    if cycles >= 2 * MEAN_CYCLES:
        return 0.0
    # Gauss-Legendre in ρ (weight 2ρ: the disc's area), the midpoint rule in the angle
    # (periodic, so as exact) over one quadrant: the band is even in hx and in hy.
    rho, w, hx, hy = _mean_grid()
    values = band_cell(hx, hy, mu_f, alpha, beta, cell).mean(1)
    mean = float((w * rho * values).sum())
    return mean * min(max(2.0 - cycles / MEAN_CYCLES, 0.0), 1.0)


def bands_resolved(mu_f: float, alpha: float, beta: float, per_wavelength: int) -> bool:
    """Whether what the samples carry, the filtered band minus ``band_mean``, can exceed
    BAND_FLOOR anywhere on the lobe; two bounds, the smaller taken:

    - steep bands: the phase's slope |∇(mu_f·r)| is at least s = mu_f·√min(α, β) (the
      positive ones), its larger component at least s/√2, and |sinc(x/2)| ≤ 2/x: the
      filtered band is at most 2√2/(2π·cell·s), the remainder that plus |mean|;
    - slow bands: over the disc the phase spans P = mu_f·√max(α, β) cycles; at P ≤ ½ the
      band lies in [cos 2πP, 1], and the filter's two sincs, each in [sinc(π·cell·P), 1]
      while cell·P < 1, scale it by at least sinc²: the filtered band, and so its mean,
      lie within (1 − cos 2πP) + (1 − sinc²) of each other. At P = 0 (mu_f or α and β
      zero) that is 0."""
    cell = cell_side(per_wavelength)
    mean = band_mean(mu_f, alpha, beta, cell)
    bounds = []
    steep = [a for a in (alpha, beta) if a > 0.0]
    slope = mu_f * math.sqrt(min(steep)) if steep else 0.0
    if slope > 0.0:
        bounds.append(2.0 * math.sqrt(2.0) / (TWO_PI * cell * slope) + abs(mean))
    cycles = mu_f * math.sqrt(max(alpha, beta, 0.0))
    if cycles <= 0.5 and cell * cycles < 1.0:
        shrink = float(sinc_half(TWO_PI * cell * cycles)) ** 2
        bounds.append((1.0 - math.cos(TWO_PI * cycles)) + (1.0 - shrink))
    return min(bounds, default=math.inf) > BAND_FLOOR
