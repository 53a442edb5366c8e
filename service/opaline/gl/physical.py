"""Defines and uniforms of the physical iridescence sources (glsl/lib/thin_film.glsl,
glsl/lib/grating.glsl): a material with ``iridescence`` other than ``rotation``
compiles the A-S lobe with its source's define, and nothing of the paper's
rotation or multi-peak MDF."""

from __future__ import annotations

import moderngl
import numpy as np

from opaline.model import grating, visible
from opaline.model.spectrum import sample_wavelengths


def is_physical(material) -> bool:
    return material.iridescence != "rotation"


def defines(material) -> dict[str, int | bool]:
    """Overrides of the paper's feature defines for a physical material."""
    if not is_physical(material):
        return {}  # the paper's variants stay exactly as they were
    thin_film = material.iridescence == "thin-film"
    return {
        "IRIDESCENCE_THIN_FILM": thin_film,
        "IRIDESCENCE_GRATING": not thin_film,
        "MDF_ASHIKHMIN": True,
        "MDF_MULTIPEAK": False,
        "AA_ANALYTIC": False,
        # The film's Airy reflectance is its Fresnel term; a grating keeps Schlick's
        # (the reflectance of its coating) where f0 < 1.
        "FRESNEL": not thin_film and material.f0 < 1.0,
        # A define so the order and Bessel loops unroll (glsl/lib/grating.glsl).
        "GRATING_ORDERS": False if thin_film else material.grating_orders,
    }


def uniforms(material, wavelengths: int) -> dict[str, object]:
    if not is_physical(material):
        return {}
    values: dict[str, object] = {
        "u_film_ior": material.film_ior,
        "u_substrate_ior": material.substrate_ior,
        "u_film_thickness_min": material.film_thickness_min,
        "u_film_thickness_max": material.film_thickness_max,
        "u_grating_pitch_nm": 1000.0 * material.grating_pitch,
        "u_grating_depth_nm": material.grating_depth,
    }
    if wavelengths > 0:
        values["u_wavelength_nm"] = [float(x) for x in sample_wavelengths(wavelengths)]
    else:
        gaussians = visible.sensitivity_gaussians()
        values["u_film_sens_weight"] = [tuple(g) for g in gaussians[..., 0]]
        values["u_film_sens_centre"] = [tuple(g) for g in gaussians[..., 1]]
        values["u_film_sens_sigma"] = [tuple(g) for g in gaussians[..., 2]]
        values["u_visible_density"] = [tuple(row) for row in visible.density_table()[1]]
        values["u_channel_nm"] = tuple(float(x) for x in grating.channel_wavelengths())
    return values


THICKNESS_UNIT = 2


def thickness_texture(ctx: moderngl.Context, field) -> moderngl.Texture | None:
    """A thickness field as a tiling, mipmapped one-channel float texture."""
    if field is None:
        return None
    height, width = field.shape
    # Rows flipped: the field's row 0 is v = 1 (image convention), GL's is v = 0.
    data = np.ascontiguousarray(field[::-1].astype("f4"))
    texture = ctx.texture((width, height), 1, data.tobytes(), dtype="f4")
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = True
    return texture


def uses_thickness_map(material, preset) -> bool:
    return material.iridescence == "thin-film" and preset.thickness_map is not None


def uses_transmission(material, preset) -> bool:
    return material.iridescence == "thin-film" and preset.transmission


def backdrop_radiance(background, tonemap: str, exposure: float) -> tuple[float, float, float]:
    """The linear radiance that displays as the preset's background colour after exposure,
    tone map and sRGB encoding: what a film that transmits everything lets through."""
    from opaline.model.reference import srgb_decode

    y = np.clip(srgb_decode(np.asarray(background, dtype=np.float64)), 0.0, 0.999)
    if tonemap == "reinhard":
        x = y / (1.0 - y)
    elif tonemap == "aces":
        # Inverse of the Narkowicz fit y = x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14).
        a, b, c = 2.51 - 2.43 * y, 0.03 - 0.59 * y, -0.14 * y
        x = (-b + np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)
    else:
        x = y
    return tuple(float(v) for v in x / exposure)
