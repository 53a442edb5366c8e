"""Continuous spectrum (docs/design.md §4.1): per-wavelength rotations and CIE weights.

Wavelength λ gets the rotation θ(λ) interpolated piecewise-linearly through
(612 nm, 0), (549 nm, θ1), (465 nm, θ2) and extended linearly beyond them. The
MDF at each wavelength is weighted by the CIE 1931 2° colour matching
functions (from colour-science), taken to linear sRGB and white balanced so a
flat spectrum (equal D everywhere) gives equal R, G, B.
"""

from __future__ import annotations

import warnings
from functools import lru_cache
from typing import Any

import numpy as np

ANCHORS_NM = (612.0, 549.0, 465.0)  # where θ = 0, θ1, θ2: the paper's R, G, B
RANGE_NM = (380.0, 780.0)


def sample_wavelengths(count: int) -> np.ndarray:
    """Midpoints of ``count`` equal bins over the visible range."""
    lo, hi = RANGE_NM
    return lo + (np.arange(count) + 0.5) * (hi - lo) / count


def rotation_at(wavelengths: np.ndarray, theta1: float, theta2: float) -> np.ndarray:
    """θ(λ) through the three anchors, linear between and beyond them."""
    lam = np.asarray(wavelengths, dtype=np.float64)
    xs = np.array(ANCHORS_NM[::-1])  # increasing: 465, 549, 612
    ys = np.array([theta2, theta1, 0.0])
    inside = np.interp(lam, xs, ys)
    below = ys[0] + (lam - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])
    above = ys[2] + (lam - xs[2]) * (ys[2] - ys[1]) / (xs[2] - xs[1])
    return np.where(lam < xs[0], below, np.where(lam > xs[2], above, inside))


def _import_colour() -> Any:
    """colour-science, imported late: it is slow to import and only spectral renders need it.

    Without matplotlib (not a dependency: Opaline uses none of colour's plotting) its import
    warns that the plotting API is unavailable; only that warning is silenced."""
    with warnings.catch_warnings():
        warnings.filterwarnings(
            "ignore", message='"Matplotlib" related API features are not available')
        import colour
    return colour


@lru_cache(maxsize=32)
def rgb_weights(count: int) -> np.ndarray:
    """(count, 3) weights from per-wavelength D to linear sRGB; columns sum to 1."""
    colour = _import_colour()
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    lam = sample_wavelengths(count)
    xyz = np.array([cmfs[w] for w in lam])  # (count, 3), interpolated by colour-science
    to_rgb = colour.models.RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB
    rgb = xyz @ to_rgb.T
    weights = rgb / rgb.sum(axis=0, keepdims=True)
    weights.setflags(write=False)  # cached and shared: a caller must not change it in place
    return weights
