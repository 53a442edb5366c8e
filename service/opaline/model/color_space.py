"""Output colour spaces: their primaries, how a colour outside them is brought in, and
their transfer curves (float64 twin of the shader's in glsl/lib/display.glsl).

Opaline shades in linear sRGB whose channels may go below 0: a spectral sum of a
saturated film or stack (a cyan sRGB cannot hold) keeps its negative channel to the
display encoding. There the colour goes to the output's primaries and, if a channel is
still below 0, toward the grey of its own luminance until none is: luminance and hue
kept, chroma lowered (bench/gamut.py measured the per-channel clip this replaced moving
hue 4.3° on average on films, this 0.6°). Display P3 and Rec. 2020 hold every film and
stack colour the benchmark drew that sRGB cannot.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
import numpy.typing as npt

from opaline.model.microfacet import FloatArray

ColorSpace = Literal["srgb", "display-p3", "rec2020"]
COLOR_SPACES: tuple[str, ...] = get_args(ColorSpace)

D65_XY = (0.3127, 0.3290)
# CIE 1931 xy of the red, green and blue primaries: IEC 61966-2-1 (sRGB, Rec. 709's),
# SMPTE EG 432-1 (Display P3: DCI-P3's primaries, D65 white), ITU-R BT.2020.
PRIMARIES: dict[str, tuple[tuple[float, float], ...]] = {
    "srgb": ((0.640, 0.330), (0.300, 0.600), (0.150, 0.060)),
    "display-p3": ((0.680, 0.320), (0.265, 0.690), (0.150, 0.060)),
    "rec2020": ((0.708, 0.292), (0.170, 0.797), (0.131, 0.046)),
}
# Display P3 uses the sRGB curve; Rec. 2020 its own (Rec. 709's OETF), as its ICC profile
# and its cICP code (transfer 1) say.
BT709_ALPHA = 1.09929682680944
BT709_BETA = 0.018053968510807
SRGB_LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # Y of linear sRGB, as the shader weighs it


def _xyz(xy: tuple[float, float]) -> FloatArray:
    x, y = xy
    return np.array([x / y, 1.0, (1.0 - x - y) / y])


def rgb_to_xyz(space: str) -> FloatArray:
    """The 3×3 matrix from linear RGB in ``space`` to XYZ (white Y = 1)."""
    columns = np.stack([_xyz(p) for p in PRIMARIES[space]], axis=1)
    scale = np.linalg.solve(columns, _xyz(D65_XY))
    matrix: FloatArray = columns * scale[None, :]
    return matrix


def from_srgb(space: str) -> FloatArray:
    """Linear sRGB to linear ``space``: both D65, so no white adaptation."""
    matrix: FloatArray = np.asarray(np.linalg.solve(rgb_to_xyz(space), rgb_to_xyz("srgb")),
                                    dtype=np.float64)
    return matrix


def luminance(space: str) -> FloatArray:
    """Each channel's share of Y in ``space``."""
    row: FloatArray = rgb_to_xyz(space)[1]
    return row


def gamut_map(x: npt.ArrayLike, space: str) -> FloatArray:
    """A linear colour in ``space`` (colours on the last axis) moved toward the grey of its
    own luminance until no channel is below 0; black where the luminance is not above 0."""
    x = np.asarray(x, dtype=np.float64)
    y = (x @ luminance(space))[..., None]
    low = x.min(axis=-1, keepdims=True)
    keep = y / np.where(low < 0.0, y - low, 1.0)
    moved = np.where(low < 0.0, np.maximum(y + keep * (x - y), 0.0), x)
    mapped: FloatArray = np.where(y > 0.0, moved, 0.0)
    return mapped


def encode(x: npt.ArrayLike, space: str) -> FloatArray:
    """The output's transfer curve over [0, 1]."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    if space == "rec2020":
        return np.where(x < BT709_BETA, 4.5 * x, BT709_ALPHA * np.power(x, 0.45)
                        - (BT709_ALPHA - 1.0))
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def decode(v: npt.ArrayLike, space: str) -> FloatArray:
    """``encode``'s inverse."""
    v = np.clip(np.asarray(v, dtype=np.float64), 0.0, 1.0)
    if space == "rec2020":
        knee = 4.5 * BT709_BETA
        return np.where(v < knee, v / 4.5,
                        np.power((v + BT709_ALPHA - 1.0) / BT709_ALPHA, 1.0 / 0.45))
    return np.where(v <= 0.04045, v / 12.92, np.power((v + 0.055) / 1.055, 2.4))


def radiance_floor(rgb: npt.ArrayLike) -> FloatArray:
    """Black where a colour's sRGB luminance is not above 0 (glsl/lib/common.glsl): a fit's
    ringing or an estimator's negative pass is no radiance; a channel below 0 under a
    luminance above 0 is a colour outside sRGB, kept."""
    rgb = np.asarray(rgb, dtype=np.float64)
    out: FloatArray = np.where((rgb @ SRGB_LUMINANCE > 0.0)[..., None], rgb, 0.0)
    return out


def display_background(background: npt.ArrayLike, space: str) -> FloatArray:
    """A preset's background (display sRGB) as the same colour's display values in
    ``space``: sRGB's colours all lie inside the wider spaces."""
    linear = decode(background, "srgb") @ from_srgb(space).T
    return encode(linear, space)
