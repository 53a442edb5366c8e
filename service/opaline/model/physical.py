"""Specular reflection of the physical iridescence sources, in a shading frame.

The float64 twin of the ``IRIDESCENCE_THIN_FILM`` / ``IRIDESCENCE_GRATING``
branches of glsl/lib/reflectance.glsl; ``reference.specular`` hands over to
``specular`` here when a material's ``iridescence`` is not ``rotation``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from opaline.model import grating, metals, stack_film, thinfilm
from opaline.model.microfacet import EPS_DENOM, EPS_HALF, FloatArray, Frame, mdf_ashikhmin

if TYPE_CHECKING:
    from opaline.model.params import Material


def is_physical(material: Material) -> bool:
    return getattr(material, "iridescence", "rotation") != "rotation"


def specular_thin_film(
    material: Material,
    frame: Frame,
    l: FloatArray,
    v: FloatArray,
    wavelengths: int = 0,
    thickness_nm: npt.ArrayLike | None = None,
) -> FloatArray:
    """ks·D(h)·R_film(v·h)/(4·(v·h)·max(n·l, n·v)): the paper's reflectance with the
    Airy reflectance of the film in place of Fresnel, and the unrotated A-S lobe."""
    t, b, n = frame
    sum_lv = l + v
    length = np.linalg.norm(sum_lv, axis=-1, keepdims=True)
    h = sum_lv / np.maximum(length, 1e-30)
    hx, hy, hz = (np.sum(h * axis, axis=-1) for axis in (t, b, n))
    d = mdf_ashikhmin(hx, hy, hz, material.ex, material.ey)
    vh = np.sum(v * h, axis=-1)
    nl = np.sum(n * l, axis=-1)
    nv = np.sum(n * v, axis=-1)
    thickness = material.film_thickness_max if thickness_nm is None else thickness_nm
    if stack_film.is_stack(material):
        film = stack_film.stack_layer_rgb(material, vh, thickness, wavelengths)
    else:
        substrate = metals.substrate_for(material, wavelengths)
        film = thinfilm.film_layer_rgb(vh, thickness, material.film_ior, substrate,
                                       material.film_weight, wavelengths)
    denom = 4.0 * np.maximum(vh, EPS_DENOM) * np.maximum(np.maximum(nl, nv), EPS_DENOM)
    spec = material.ks * film * (d / denom)[..., None]
    return np.where(length > EPS_HALF, spec, 0.0)


def specular_grating(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, wavelengths: int = 0
) -> FloatArray:
    if wavelengths > 0:
        colour = grating.grating_spectral(material, frame, l, v, wavelengths)
    else:
        colour = grating.grating_fast(material, frame, l, v)
    return material.ks * colour


def specular(
    material: Material, frame: Frame, l: FloatArray, v: FloatArray, wavelengths: int = 0
) -> FloatArray:
    if material.iridescence == "thin-film":
        return specular_thin_film(material, frame, l, v, wavelengths)
    return specular_grating(material, frame, l, v, wavelengths)
