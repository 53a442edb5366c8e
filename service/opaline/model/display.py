"""Float64 twin of the display encoding (glsl/lib/display.glsl): tone maps, their
inverses (for the backdrop a transmitting film lets through), the sRGB transfer, and the
whole encoding into an output colour space (model/color_space.py).

Colours are on the last axis where a tone map mixes channels (``neutral``); the
per-channel maps broadcast over any shape.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from opaline.model import color_space
from opaline.model.microfacet import FloatArray

# Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral/README.md): F90 is the
# normal-incidence Fresnel of an IoR 1.5 dielectric, the offset that makes a white-lit
# base colour in 0.08 … 0.8 come out exactly; compression starts at KS, and KD sets how
# fast the compressed peak desaturates toward white.
F90 = 0.04
KS = 0.8 - F90
KD = 0.15


def neutral(x: npt.ArrayLike) -> FloatArray:
    """PBR Neutral: every change stays in the plane of the colour and the grey axis, so the
    hue about that axis is kept; only a peak above KS is compressed (toward 1, and white)."""
    x = np.maximum(np.asarray(x, dtype=np.float64), 0.0)
    low = x.min(axis=-1, keepdims=True)
    x = x - np.where(low <= 2.0 * F90, low - low * low / (4.0 * F90), F90)
    peak = x.max(axis=-1, keepdims=True)
    d = 1.0 - KS
    above = np.maximum(peak, KS)  # the compressed branch, evaluated safely everywhere
    new_peak = 1.0 - d * d / (above + d - KS)
    g = 1.0 / (KD * (above - new_peak) + 1.0)
    return np.where(peak <= KS, x, x * (new_peak / above) * g + new_peak * (1.0 - g))


def neutral_inverse(y: npt.ArrayLike) -> FloatArray:
    """The colour ``neutral`` maps to ``y`` (max < 1); a colour the map cannot reach (too
    saturated that close to white) comes back with its negative channels at 0."""
    y = np.asarray(y, dtype=np.float64)
    new_peak = y.max(axis=-1, keepdims=True)
    d = 1.0 - KS
    above = np.maximum(new_peak, KS)
    peak = d * d / (1.0 - above) - d + KS
    g = 1.0 / (KD * (peak - above) + 1.0)
    shifted = np.where(new_peak <= KS, y, (y - above * (1.0 - g)) * peak / (above * g))
    shifted = np.maximum(shifted, 0.0)
    # min(shifted) = 6.25·low² below low = 2·F90, else low − F90: recover the offset.
    m = shifted.min(axis=-1, keepdims=True)
    low = np.sqrt(m * 4.0 * F90)
    return shifted + np.where(m <= F90, low - m, F90)


def tonemap(x: npt.ArrayLike, mode: str) -> FloatArray:
    if mode == "neutral":
        return neutral(x)
    x = np.maximum(x, 0.0)
    if mode == "reinhard":
        return x / (1.0 + x)
    if mode == "aces":
        # Narkowicz 2015 fit of the ACES filmic curve.
        return np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
    return np.clip(x, 0.0, 1.0)


def tonemap_inverse(y: npt.ArrayLike, mode: str) -> FloatArray:
    """The linear colour that ``tonemap`` maps to ``y`` (each channel in [0, 1))."""
    y = np.asarray(y, dtype=np.float64)
    if mode == "neutral":
        return neutral_inverse(y)
    if mode == "reinhard":
        return y / (1.0 - y)
    if mode == "aces":
        # Inverse of the Narkowicz fit y = x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14).
        a, b, c = 2.51 - 2.43 * y, 0.03 - 0.59 * y, -0.14 * y
        return (-b + np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)
    return y


def srgb_encode(x: npt.ArrayLike) -> FloatArray:
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_decode(x: npt.ArrayLike) -> FloatArray:
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


def display_encode(linear_srgb: npt.ArrayLike, mode: str, space: str = "srgb") -> FloatArray:
    """Exposed linear sRGB radiance (colours on the last axis) to display values in
    ``space``: its primaries, its gamut, the tone map, its transfer curve."""
    x = np.asarray(linear_srgb, dtype=np.float64) @ color_space.from_srgb(space).T
    return color_space.encode(tonemap(color_space.gamut_map(x, space), mode), space)
