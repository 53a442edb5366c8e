"""Float64 NumPy reference of the shading model (docs/design.md §1).

Each function mirrors one GLSL function in ``glsl/lib`` of the same name, so
tests can compare the two path by path. All functions broadcast over arrays.

References: Kang, Lee, Cho 2014 (eqs. 1-4); Ashikhmin & Shirley 2000 for the
reflectance around the MDF; Schlick 1994 for the Fresnel term.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from opaline.model import coat

# Re-exported (as X as X, for the type checker): the reference in one place.
from opaline.model.color_space import radiance_floor
from opaline.model.display import srgb_decode as srgb_decode
from opaline.model.display import srgb_encode as srgb_encode
from opaline.model.display import tonemap as tonemap
from opaline.model.microfacet import (  # noqa: F401 (re-exported: the reference in one place)
    EPS_DENOM,
    EPS_HALF,
    FloatArray,
    Frame,
    Values,
    fresnel_schlick,
    log1p_ratio,
    mdf_ashikhmin,
)
from opaline.model.spectrum import CENTRE, rgb_weights, rotation_at, sample_wavelengths

if TYPE_CHECKING:
    from opaline.model.params import Material

TWO_PI = 2.0 * np.pi


def rotate_half(hx: FloatArray, hy: FloatArray, theta: float) -> tuple[FloatArray, FloatArray]:
    """Eq. 2: rotate the projected half vector counter-clockwise by ``theta``."""
    c, s = np.cos(theta), np.sin(theta)
    return c * hx - s * hy, s * hx + c * hy


def mdf_multipeak(
    hx: FloatArray, hy: FloatArray, hz: FloatArray, mu_f: float, alpha: float, beta: float
) -> FloatArray:
    """Eqs. 3-4: ½·max(hz, 0)·(cos(2π·mu_f·r) + 1), r = sqrt(α·hx² + β·hy²)."""
    r = np.sqrt(alpha * hx * hx + beta * hy * hy)
    return 0.5 * np.maximum(hz, 0.0) * (np.cos(TWO_PI * mu_f * r) + 1.0)


def sinc_half(footprint: npt.ArrayLike) -> FloatArray:
    """sin(Δ/2)/(Δ/2): the mean of cos over a phase interval of width Δ, per unit cos."""
    half = 0.5 * np.asarray(footprint, dtype=np.float64)
    safe = np.where(half > 1e-4, half, 1.0)
    return np.where(half > 1e-4, np.sin(half) / safe, 1.0 - half * half / 6.0)


def mdf_multipeak_filtered(
    hx: FloatArray,
    hy: FloatArray,
    hz: FloatArray,
    mu_f: float,
    alpha: float,
    beta: float,
    footprint: npt.ArrayLike,
    footprint_y: npt.ArrayLike = 0.0,
) -> FloatArray:
    """Eq. 4 with the cosine box-filtered over the pixel (docs/design.md §4.2).

    ``footprint`` and ``footprint_y`` are how far the phase moves (radians) across the
    sample's box along the screen's x and y. Over a box the phase is x0 + a·u + b·v with
    u, v uniform in [-½, ½], and the mean of cos over it is cos(x0)·sinc(a/2)·sinc(b/2): a
    product of two sincs, not one sinc of |a| + |b| (which blurs where both are large).
    """
    r = np.sqrt(alpha * hx * hx + beta * hy * hy)
    x = TWO_PI * mu_f * r
    band = np.cos(x) * sinc_half(np.abs(footprint)) * sinc_half(np.abs(footprint_y))
    return 0.5 * np.maximum(hz, 0.0) * (band + 1.0)


def mdf(material: Material, hx: FloatArray, hy: FloatArray, hz: FloatArray) -> FloatArray:
    """The material's MDF at an unrotated projected half vector."""
    if material.mdf == "ashikhmin":
        return mdf_ashikhmin(hx, hy, hz, material.ex, material.ey)
    return mdf_multipeak(hx, hy, hz, material.mu_f, material.alpha, material.beta)


def mdf_rgb(
    material: Material,
    hx: FloatArray,
    hy: FloatArray,
    hz: FloatArray,
    wavelengths: int = 0,
    shift: float = CENTRE,
) -> FloatArray:
    """D for R, G, B: the MDF at half vectors rotated by 0, θ1, θ2 (eq. 2), or,
    with ``wavelengths`` > 0, per wavelength (at ``shift`` through each bin) and integrated
    to linear sRGB."""
    if wavelengths > 0:
        lam = sample_wavelengths(wavelengths, shift)
        thetas = rotation_at(lam, material.theta1, material.theta2)
        weights = rgb_weights(wavelengths, shift)
        total: Values = 0.0
        for theta, weight in zip(thetas, weights, strict=True):
            rx, ry = rotate_half(hx, hy, theta)
            total = total + mdf(material, rx, ry, hz)[..., None] * weight
        # A channel below 0 (outside sRGB) goes to the display's gamut map.
        return radiance_floor(total)
    out = []
    for theta in (0.0, material.theta1, material.theta2):
        rx, ry = rotate_half(hx, hy, theta)
        out.append(mdf(material, rx, ry, hz))
    return np.stack(out, axis=-1)


def normalize(v: FloatArray) -> FloatArray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    unit: FloatArray = v / np.maximum(length, 1e-30)
    return unit


def shading_frame(n: FloatArray, t: FloatArray) -> Frame:
    """Orthonormal (t, b, n): t made perpendicular to n; a t along n is replaced."""
    n = normalize(n)
    t = t - n * np.sum(n * t, axis=-1, keepdims=True)
    length = np.linalg.norm(t, axis=-1, keepdims=True)
    # Any perpendicular will do where the tangent field degenerates (sphere poles).
    fallback_axis = np.where(np.abs(n[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    fallback = np.cross(n, fallback_axis)
    t = np.where(length > 1e-6, t / np.maximum(length, 1e-30), normalize(fallback))
    # A short remainder (t nearly along n) is mostly cancellation error: a second
    # projection makes it perpendicular to working precision ("twice is enough").
    t = normalize(t - n * np.sum(n * t, axis=-1, keepdims=True))
    b = np.cross(n, t)
    return t, b, n


def specular_rgb(
    material: Material,
    n: FloatArray,
    t: FloatArray,
    l: FloatArray,
    v: FloatArray,
    wavelengths: int = 0,
) -> FloatArray:
    """``specular`` in the shading frame of ``n`` and ``t``."""
    return specular(material, shading_frame(n, t), l, v, wavelengths)


def specular(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, wavelengths: int = 0
) -> FloatArray:
    """ks·D_c·F/(4·(v·h)·max(n·l, n·v)) per channel in a (t, b, n) frame; zero where h is
    undefined."""
    if getattr(material, "iridescence", "rotation") != "rotation":
        # Imported here: the physical sources build on this module's functions.
        from opaline.model import physical

        return physical.specular(material, frame, l, v, wavelengths)
    t, b, n = frame
    sum_lv = l + v
    length = np.linalg.norm(sum_lv, axis=-1, keepdims=True)
    h = sum_lv / np.maximum(length, 1e-30)
    hx = np.sum(h * t, axis=-1)
    hy = np.sum(h * b, axis=-1)
    hz = np.sum(h * n, axis=-1)
    d = mdf_rgb(material, hx, hy, hz, wavelengths)
    vh = np.sum(v * h, axis=-1)
    nl = np.sum(n * l, axis=-1)
    nv = np.sum(n * v, axis=-1)
    f = fresnel_schlick(material.f0, vh)
    denom = 4.0 * np.maximum(vh, EPS_DENOM) * np.maximum(np.maximum(nl, nv), EPS_DENOM)
    spec = material.ks * d * (f / denom)[..., None]
    return np.where(length > EPS_HALF, spec, 0.0)


def reflected_radiance(
    material: Material,
    n: FloatArray,
    t: FloatArray,
    l: FloatArray,
    v: FloatArray,
    wavelengths: int = 0,
) -> FloatArray:
    """f·max(n·l, 0) for a light of unit irradiance, per channel (linear RGB)."""
    frame = shading_frame(n, t)
    nl = np.sum(frame[2] * l, axis=-1)
    diffuse = material.kd * np.asarray(material.albedo, dtype=np.float64) / np.pi
    f = diffuse + specular(material, frame, l, v, wavelengths)
    f = coat.layered(material, frame, l, v, f)
    radiance: FloatArray = f * np.maximum(nl, 0.0)[..., None]
    return radiance


def mdf_plot_coords(size: int) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """Pixel-centre hx, hy, hz of the N×N MDF plot (row 0 at the top, +hy up)."""
    centres = (np.arange(size, dtype=np.float64) + 0.5) / size * 2.0 - 1.0
    hx, hy = np.meshgrid(centres, centres[::-1])
    s2 = hx * hx + hy * hy
    hz = np.sqrt(np.maximum(1.0 - s2, 0.0))
    return hx, hy, hz, s2 < 1.0


def mdf_plot(material: Material, size: int, wavelengths: int = 0) -> FloatArray:
    """The paper's Figs. 2, 3, 6, 7: D over the projected half-vector disc, R G B."""
    hx, hy, hz, inside = mdf_plot_coords(size)
    return np.where(inside[..., None], mdf_rgb(material, hx, hy, hz, wavelengths), 0.0)
