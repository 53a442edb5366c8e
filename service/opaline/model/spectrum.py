"""Continuous spectrum (docs/design.md §4.1): per-wavelength rotations and CIE weights.

Wavelength λ gets the rotation θ(λ) interpolated piecewise-linearly through
(612 nm, 0), (549 nm, θ1), (465 nm, θ2) and held constant beyond them (θ2
below 465 nm, 0 above 612 nm): the paper gives rotations for its three
primaries only, and extending the lines invents rotations up to ±19 rad at
θ = ±2π that no RGB render has and that need hundreds of wavelengths to
converge (docs/accuracy.md, "Spectral extremes"). The MDF at each wavelength is
weighted by the CIE 1931 2° colour matching functions (from colour-science),
taken to linear sRGB and white balanced so a flat spectrum (equal D
everywhere) gives equal R, G, B.

Supersampled renders move the wavelengths from sample to sample (``shift``):
sample i takes bin positions shifted by a golden-ratio sequence, so N samples
of W wavelengths integrate the spectrum at N·W points instead of W.
"""

from __future__ import annotations

import warnings
from functools import lru_cache
from typing import Any

import numpy as np

ANCHORS_NM = (612.0, 549.0, 465.0)  # where θ = 0, θ1, θ2: the paper's R, G, B
RANGE_NM = (380.0, 780.0)
CENTRE = 0.5  # one sample (and the float64 twin by default) takes the bins' midpoints
_GOLDEN = 0.6180339887498949  # 1/φ: the 1-D sequence that covers [0, 1) well for every n


def sample_wavelengths(count: int, shift: float = CENTRE) -> np.ndarray:
    """``count`` points at ``shift`` (0 … 1) of the way through equal bins over the visible
    range: the midpoints by default."""
    lo, hi = RANGE_NM
    return lo + (np.arange(count) + shift) * (hi - lo) / count


def wavelength_shift(index: int, samples: int) -> float:
    """Where in its bin supersample ``index`` of ``samples`` puts its wavelengths."""
    if samples <= 1:
        return CENTRE
    return float((CENTRE + index * _GOLDEN) % 1.0)


def rotation_at(wavelengths: np.ndarray, theta1: float, theta2: float) -> np.ndarray:
    """θ(λ) through the three anchors, linear between them and constant beyond them."""
    lam = np.asarray(wavelengths, dtype=np.float64)
    xs = np.array(ANCHORS_NM[::-1])  # increasing: 465, 549, 612
    ys = np.array([theta2, theta1, 0.0])
    return np.interp(lam, xs, ys)  # np.interp holds the end values outside xs


def _import_colour() -> Any:
    """colour-science, imported late: it is slow to import and only spectral renders need it.

    Without matplotlib (not a dependency: Opaline uses none of colour's plotting) its import
    warns that the plotting API is unavailable; only that warning is silenced."""
    with warnings.catch_warnings():
        warnings.filterwarnings(
            "ignore", message='"Matplotlib" related API features are not available')
        import colour
    return colour


@lru_cache(maxsize=256)
def rgb_weights(count: int, shift: float = CENTRE) -> np.ndarray:
    """(count, 3) weights from per-wavelength D to linear sRGB; columns sum to 1."""
    colour = _import_colour()
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    lam = sample_wavelengths(count, shift)
    xyz = np.asarray(cmfs[lam])  # (count, 3), interpolated by colour-science
    to_rgb = colour.models.RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB
    rgb = xyz @ to_rgb.T
    weights = rgb / rgb.sum(axis=0, keepdims=True)
    weights.setflags(write=False)  # cached and shared: a caller must not change it in place
    return weights
