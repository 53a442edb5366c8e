"""Float64 twin of glsl/lib/thin_film_stack.glsl: a film that is a multilayer stack.

``film_stack_pairs`` = N > 0 makes the film (HL)^N on the substrate: N periods of a layer
of ``film_ior`` and the film's thickness d over a spacer of ``film_spacer_ior`` and
``film_spacer_thickness``·d/``film_thickness_max`` (a thickness field swells the whole
period). The reflectance is the characteristic matrix's (``model/multilayer.py``, held to
colour-science there); the shader builds the same amplitude by Rouard's recursion. The
spectral path integrates the job's wavelengths; the fast path, which has no closed form
for a stack, ``STACK_BINS`` bins of its own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from opaline.model import metals, thinfilm
from opaline.model.color_space import radiance_floor
from opaline.model.multilayer import stack_optics
from opaline.model.spectrum import rgb_weights, sample_wavelengths

if TYPE_CHECKING:
    from opaline.model.params import Material

STACK_BINS = 16  # the fast path's bins (glsl/lib/thin_film_stack.glsl)


def is_stack(material: Material) -> bool:
    return material.iridescence == "thin-film" and material.film_stack_pairs > 0


def stack_bins(wavelengths: int) -> int:
    """The bins a stack is integrated over: the spectral path's, or the fast path's own."""
    return wavelengths if wavelengths > 0 else STACK_BINS


def bin_substrate(material: Material, wavelengths: int) -> complex | np.ndarray:
    """The substrate's index at each bin: real for a dielectric, n + ik for a metal."""
    if material.substrate != "conductor":
        return complex(material.substrate_ior)
    return metals.substrate_index(material, sample_wavelengths(stack_bins(wavelengths)))


def stack_reflectance(material: Material, cos1: npt.ArrayLike, d_nm: npt.ArrayLike,
                      wavelengths: int = 0) -> np.ndarray:
    """R(λ) of the stack at each bin (last axis), s and p averaged; 1 at grazing."""
    cos1 = np.clip(np.asarray(cos1, dtype=np.float64), 0.0, 1.0)[..., None]
    d = np.asarray(d_nm, dtype=np.float64)[..., None]
    lam = sample_wavelengths(stack_bins(wavelengths))
    scale = d / material.film_thickness_max if material.film_thickness_max > 0.0 else 1.0
    spacer = material.film_spacer_thickness * scale
    layers = [material.film_ior, material.film_spacer_ior] * material.film_stack_pairs
    thicknesses = np.broadcast_arrays(d, spacer)
    # At grazing (cos 0) the p admittance is infinite: the answer there is 1 (below).
    optics = stack_optics(layers, thicknesses * material.film_stack_pairs, lam,
                          np.maximum(cos1, 1e-9),
                          substrate=bin_substrate(material, wavelengths))
    r: np.ndarray = np.where(cos1 > 0.0, optics.reflectance, 1.0)
    return r


def stack_rgb(material: Material, cos1: npt.ArrayLike, d_nm: npt.ArrayLike,
              wavelengths: int = 0) -> np.ndarray:
    """Σ_i w_i·R(λ_i) in linear sRGB; a channel below 0 (outside sRGB) is kept, as the
    shader keeps it, for the display's gamut map."""
    weights = rgb_weights(stack_bins(wavelengths))
    rgb: np.ndarray = radiance_floor(stack_reflectance(material, cos1, d_nm, wavelengths)
                                     @ weights)
    return rgb


def stack_layer_rgb(material: Material, cos1: npt.ArrayLike, d_nm: npt.ArrayLike,
                    wavelengths: int = 0) -> np.ndarray:
    """mix(bare substrate, stack, film_weight), as the single film's layering."""
    stack = stack_rgb(material, cos1, d_nm, wavelengths)
    if material.film_weight >= 1.0:
        return stack
    base = thinfilm.film_base_rgb(cos1, metals.substrate_for(material, wavelengths), wavelengths)
    mixed: np.ndarray = base + material.film_weight * (stack - base)
    return mixed
