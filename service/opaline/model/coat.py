"""A clear coat over the whole material: the float64 twin of glsl/lib/coat.glsl.

The layering is KHR_materials_clearcoat's (and the glTF Sample Viewer's): seen from v,
the coat reflects w·F_c of what meets it and the base below is dimmed to
1 − w·F_c(n·v); the coat's own reflection is a specular lobe of its own,

    f = f_base·(1 − w·F_c(n·v)) + w·D_c(h)·F_c(v·h) / (4·(v·h)·max(n·l, n·v)),

F_c Schlick's Fresnel of the coat's index against air and D_c an isotropic
Ashikhmin-Shirley lobe whose exponent has the width of the GGX lobe of the coat's
roughness. As in KHR, the base is not dimmed on the light's side and the coat does
not change the medium above a thin film (air); docs/physics.md §1.5 says what that
leaves out.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from opaline.model.microfacet import (
    EPS_DENOM,
    EPS_HALF,
    FloatArray,
    Frame,
    fresnel_schlick,
    mdf_ashikhmin,
)

if TYPE_CHECKING:
    from opaline.model.material import Material

# glTF's roughness r is perceptual: the GGX width is α = r² (glTF 2.0 spec, appendix B),
# and the A-S (Blinn-Phong) exponent of the same width is n = 2/α² - 2 (Walter et al.
# 2007, §5.2), so n = 2/r⁴ - 2; roughness 0.1 is n ≈ 20 000, not the 198 of r read as α.
EXPONENT_MAX = 1e6  # Material's range for ex and ey
ROUGHNESS_MIN = 0.02  # as glTF importers clamp it: n reaches EXPONENT_MAX above it


def exponent_from_roughness(roughness: float) -> float:
    """The A-S exponent of a glTF roughness (clamped to [0.02, 1] as importers do)."""
    alpha = float(np.clip(roughness, ROUGHNESS_MIN, 1.0)) ** 2
    return float(min(2.0 / alpha**2 - 2.0, EXPONENT_MAX))


def roughness_from_exponent(exponent: float) -> float:
    """glTF roughness of an A-S exponent: the inverse of ``exponent_from_roughness``."""
    alpha = np.sqrt(2.0 / (max(exponent, 0.0) + 2.0))
    return float(np.clip(np.sqrt(alpha), ROUGHNESS_MIN, 1.0))


def has_coat(material: Material) -> bool:
    # The reference also shades the paper's parameter sets, which have no coat.
    return float(getattr(material, "coat_weight", 0.0)) > 0.0


def coat_f0(ior: float) -> float:
    """Reflectance at normal incidence of the coat's index against air."""
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def coat_keep(material: Material, nv: FloatArray) -> FloatArray:
    """What of the base the coat lets through toward v: 1 − w·F_c(n·v)."""
    fresnel = fresnel_schlick(coat_f0(material.coat_ior), np.clip(nv, 0.0, 1.0))
    return 1.0 - material.coat_weight * np.asarray(fresnel, dtype=np.float64)


def coat_specular(material: Material, frame: Frame, l: FloatArray, v: FloatArray) -> FloatArray:
    """w·D_c(h)·F_c(v·h)/(4·(v·h)·max(n·l, n·v)), grey: zero where h is undefined."""
    t, b, n = frame
    sum_lv = l + v
    length = np.linalg.norm(sum_lv, axis=-1)
    h = sum_lv / np.maximum(length, 1e-30)[..., None]
    hx, hy, hz = (np.sum(h * axis, axis=-1) for axis in (t, b, n))
    exponent = exponent_from_roughness(material.coat_roughness)
    d = mdf_ashikhmin(hx, hy, hz, exponent, exponent)
    vh = np.sum(v * h, axis=-1)
    nl = np.sum(n * l, axis=-1)
    nv = np.sum(n * v, axis=-1)
    fresnel = fresnel_schlick(coat_f0(material.coat_ior), vh)
    denom = 4.0 * np.maximum(vh, EPS_DENOM) * np.maximum(np.maximum(nl, nv), EPS_DENOM)
    spec: FloatArray = np.where(length > EPS_HALF, material.coat_weight * d * fresnel / denom,
                                0.0)
    return spec


def layered(material: Material, frame: Frame, l: FloatArray, v: FloatArray,
            base: FloatArray) -> FloatArray:
    """``base`` (f per channel, ``(..., 3)``) under the coat, with the coat's own lobe."""
    if not has_coat(material):
        return base
    nv = np.sum(frame[2] * v, axis=-1)
    coated: FloatArray = (base * coat_keep(material, nv)[..., None]
                          + coat_specular(material, frame, l, v)[..., None])
    return coated


def coat_albedo(material: Material, cos_v: float, steps: int = 512) -> float:
    """∫ coat_specular·(n·l) dω_l toward a view at ``cos_v`` to n, by quadrature over the
    half vector's hemisphere (dω_l = 4·(v·h)·dω_h): what a white map's coat reflects."""
    exponent = exponent_from_roughness(material.coat_roughness)
    # Polar angle of h on a grid that resolves the lobe's width, azimuth uniform.
    width = min(np.pi / 2, 6.0 / np.sqrt(exponent + 2.0))
    theta = (np.arange(steps) + 0.5) / steps * width
    phi = (np.arange(2 * steps) + 0.5) / (2 * steps) * 2.0 * np.pi
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    h = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    v = np.array([np.sqrt(1.0 - cos_v**2), 0.0, cos_v])
    vh = h @ v
    l = 2.0 * vh[..., None] * h - v
    frame = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]))
    f = coat_specular(material, frame, l, np.broadcast_to(v, l.shape))
    integrand = np.where((l[..., 2] > 0.0) & (vh > 0.0),
                         f * l[..., 2] * 4.0 * vh * np.sin(th), 0.0)
    return float(integrand.sum() * (width / steps) * (2.0 * np.pi / (2 * steps)))
