"""Feature defines and uniform values for a material: what a variant compiles and is fed."""

from __future__ import annotations

import math

import moderngl
import numpy as np

from opaline.gl import physical
from opaline.model.params import Material
from opaline.model.spectrum import CENTRE, rgb_weights, rotation_at, sample_wavelengths


def mdf_defines(
    material: Material, wavelengths: int = 0, aa: str = "none"
) -> dict[str, int | bool]:
    """The MDF's features alone: what the MDF plot compiles (it has no reflectance)."""
    multipeak = material.mdf == "multipeak"
    return {
        "MDF_MULTIPEAK": multipeak,
        "MDF_ASHIKHMIN": not multipeak,
        "WAVELENGTHS": wavelengths if wavelengths > 0 else False,
        "AA_ANALYTIC": multipeak and aa == "analytic",
    }


def material_defines(
    material: Material, wavelengths: int = 0, aa: str = "none"
) -> dict[str, int | bool]:
    """Only the features this material uses (docs/design.md §4.3)."""
    return {
        **mdf_defines(material, wavelengths, aa),
        "DIFFUSE": material.kd > 0.0 and max(material.albedo) > 0.0,
        "FRESNEL": material.f0 < 1.0,
        **physical.defines(material),
    }


def _cos_sin(theta: np.ndarray) -> list[tuple[float, float]]:
    return [(math.cos(a), math.sin(a)) for a in np.atleast_1d(theta)]


def material_uniforms(
    material: Material, wavelengths: int = 0, shift: float = CENTRE
) -> dict[str, object]:
    values: dict[str, object] = {
        "u_ex": material.ex,
        "u_ey": material.ey,
        "u_mu_f": material.mu_f,
        "u_alpha": material.alpha,
        "u_beta": material.beta,
        "u_ks": material.ks,
        "u_kd": material.kd,
        "u_albedo": tuple(material.albedo),
        "u_f0": material.f0,
    }
    if wavelengths > 0:
        values.update(spectral_uniforms(material, wavelengths, shift))
    else:
        values["u_rotation"] = _cos_sin(np.array([0.0, material.theta1, material.theta2]))
    values.update(physical.uniforms(material, wavelengths))
    return values


def spectral_uniforms(material: Material, wavelengths: int, shift: float) -> dict[str, object]:
    """Rotations and weights of ``wavelengths`` wavelengths at ``shift`` through their bins
    (spectrum.wavelength_shift): set again before each supersample."""
    theta = rotation_at(sample_wavelengths(wavelengths, shift), material.theta1, material.theta2)
    return {"u_spectral_rotation": _cos_sin(theta),
            "u_spectral_weight": [tuple(w) for w in rgb_weights(wavelengths, shift)]}


def apply(program: moderngl.Program, values: dict[str, object]) -> None:
    """Set the uniforms the program has; the compiler drops unused ones per variant."""
    for name, value in values.items():
        member = program.get(name, None)
        if member is None:
            continue
        if isinstance(value, np.ndarray):
            member.write(value.astype("f4").tobytes())
        elif isinstance(value, list) and member.array_length == 1:
            member.value = value[0]  # moderngl treats a one-element array as a scalar
        else:
            member.value = value
