"""Continuous spectrum (docs/design.md §4.1): per-wavelength rotations and CIE weights.

Wavelength λ gets the rotation θ(λ) interpolated piecewise-linearly through
(612 nm, 0), (549 nm, θ1), (465 nm, θ2) and held constant beyond them (θ2
below 465 nm, 0 above 612 nm): the paper gives rotations for its three
primaries only, and extending the lines invents rotations up to ±19 rad at
θ = ±2π that no RGB render has and that need hundreds of wavelengths to
converge (docs/accuracy.md, "Spectral extremes"). The MDF at each wavelength is
weighted by the CIE 1931 2° colour matching functions (colour-science's table)
under CIE illuminant D65, the white of sRGB (so a white light means D65, as an
sRGB display shows it), taken to linear sRGB and normalised so a flat spectrum
(equal D everywhere) gives R = G = B = D. Under an equal-energy white instead, a
film's converged colour was 1.0 ΔE00 (mean) from an exact D65 reference, and 0.1
under D65 (bench/white_point.py).

Supersampled renders move the wavelengths from sample to sample (``shift``):
sample i takes bin positions shifted by a golden-ratio sequence, so N samples
of W wavelengths integrate the spectrum at N·W points instead of W.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

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
    theta: np.ndarray = np.interp(lam, xs, ys)  # np.interp holds the end values outside xs
    return theta


# XYZ to linear sRGB (IEC 61966-2-1), the matrix colour-science uses for sRGB.
XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415],
                        [0.0557, -0.204, 1.057]])
# The CIE 1931 2° colour matching functions, 360-830 nm, as colour-science interpolates
# its 1 nm table (Sprague), sampled at 0.1 nm and shipped with the package: linear
# interpolation between those samples is within 1e-5 of colour-science's values, and a
# render does not pay for importing colour-science and scipy (over a second cold).
# Regenerate with tests/model/test_spectrum.py's instructions; a test compares the two.
CMFS_FILE = Path(__file__).with_name("cie1931_cmfs.npy")
# CIE standard illuminant D65, 300-780 nm by 5 nm (CIE 015, colour-science's
# SDS_ILLUMINANTS["D65"]), linearly interpolated as CIE recommends for it.
D65_FILE = Path(__file__).with_name("cie_d65.npy")


@lru_cache(maxsize=1)
def _cmfs_table() -> tuple[np.ndarray, np.ndarray]:
    data = np.load(CMFS_FILE)
    return data[:, 0], data[:, 1:]


def cie_xyz(lam: np.ndarray) -> np.ndarray:
    """x̄, ȳ, z̄ of the CIE 1931 2° observer at ``lam`` nm, shape ``lam.shape + (3,)``."""
    grid, xyz = _cmfs_table()
    lam = np.asarray(lam, dtype=np.float64)
    return np.stack([np.interp(lam, grid, xyz[:, i]) for i in range(3)], axis=-1)


@lru_cache(maxsize=1)
def _d65_table() -> tuple[np.ndarray, np.ndarray]:
    data = np.load(D65_FILE)
    return data[:, 0], data[:, 1]


def illuminant_d65(lam: np.ndarray) -> np.ndarray:
    """D65's relative spectral power at ``lam`` nm (100 at 560 nm)."""
    grid, power = _d65_table()
    result: np.ndarray = np.interp(np.asarray(lam, dtype=np.float64), grid, power)
    return result


def white_xyz(lam: np.ndarray) -> np.ndarray:
    """x̄, ȳ, z̄ weighted by the white light (D65) at ``lam``: what a reflectance of 1 there
    sends to the eye."""
    lam = np.asarray(lam, dtype=np.float64)
    result: np.ndarray = cie_xyz(lam) * illuminant_d65(lam)[..., None]
    return result


@lru_cache(maxsize=256)
def rgb_weights(count: int, shift: float = CENTRE) -> np.ndarray:
    """(count, 3) weights from per-wavelength D to linear sRGB under D65; columns sum to 1."""
    rgb = white_xyz(sample_wavelengths(count, shift)) @ XYZ_TO_SRGB.T
    weights: np.ndarray = rgb / rgb.sum(axis=0, keepdims=True)
    weights.setflags(write=False)  # cached and shared: a caller must not change it in place
    return weights
