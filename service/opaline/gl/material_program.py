"""A material, with the job's settings and the scene, as what a program compiles and is
fed: its feature defines (one per feature in use, so features that are off are not
compiled in) and its uniform values.

Two sources speak about the same defines: the paper's model (its MDF, Fresnel and
analytic filter) and a physical iridescence source (thin film, grating; docs/physics.md).
Where both do, the physical source wins, for the reasons below; every other define has
exactly one source (the scene's: normal map, tangents, lights, waves, thickness map,
transmission).

    define         paper's rule                physical source (wins)   why it wins
    MDF_MULTIPEAK  mdf == "multipeak"          False                    film and grating colour the A-S lobe
    MDF_ASHIKHMIN  mdf == "ashikhmin"          True                     (their own lobe, not the paper's peaks)
    AA_ANALYTIC    multi-peak and aa=analytic  False                    no multi-peak phase to filter
    FRESNEL        f0 < 1                      film: False;             the film's Airy reflectance is its
                                               grating: f0 < 1          Fresnel term; a grating keeps Schlick's
                                                                        (its coating's reflectance)

The MDF plot compiles the paper's MDF rule alone (``plot_defines``): it draws the
material's ``mdf`` over the half-vector disc, whatever its iridescence.
"""

from __future__ import annotations

import math

import numpy as np

from opaline.gl import environment_light, heightfield
from opaline.gl.uniforms import Uniforms
from opaline.model import coat, grating, metals, stack_film, visible
from opaline.model.params import Material
from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.model.spectrum import CENTRE, rgb_weights, rotation_at, sample_wavelengths

Defines = dict[str, int | bool]


def is_physical(material: Material) -> bool:
    return material.iridescence != "rotation"


def plot_defines(material: Material, wavelengths: int = 0, aa: str = "none") -> Defines:
    """The paper's MDF features alone: what the MDF plot compiles (it has no reflectance)."""
    multipeak = material.mdf == "multipeak"
    return {
        "MDF_MULTIPEAK": multipeak,
        "MDF_ASHIKHMIN": not multipeak,
        "WAVELENGTHS": wavelengths if wavelengths > 0 else False,
        "AA_ANALYTIC": multipeak and aa == "analytic",
    }


def _physical_defines(material: Material, orders_read: bool) -> Defines:
    """What a physical source decides, the contested defines included (the table above)."""
    thin_film = material.iridescence == "thin-film"
    # A grating's orders read from an environment map are a box filter within FLIP
    # 0.03-0.07 of the converged reads: their series is cut at READS_SERIES_TOLERANCE (its
    # lights in the same program too); everywhere else at the key light's, which is
    # checked against its float64 twin to 1e-6.
    tolerance = grating.READS_SERIES_TOLERANCE if orders_read else grating.SERIES_TOLERANCE
    return {
        "IRIDESCENCE_THIN_FILM": thin_film,
        "IRIDESCENCE_GRATING": not thin_film,
        "MDF_ASHIKHMIN": True,
        "MDF_MULTIPEAK": False,
        "AA_ANALYTIC": False,
        "FRESNEL": not thin_film and material.f0 < 1.0,
        # Defines so the order and Bessel loops unroll (glsl/lib/grating.glsl), the series
        # no longer than the grooves' depth needs.
        "GRATING_ORDERS": False if thin_film else material.grating_orders,
        "BESSEL_TERMS": False if thin_film else grating.bessel_terms(material.grating_depth,
                                                                      tolerance),
    }


def material_defines(material: Material, wavelengths: int = 0, aa: str = "none",
                     orders_read: bool = False) -> Defines:
    """Only the features this material uses (docs/design.md §4.3); ``orders_read``: a
    grating's orders are read from an environment map (gl/environment_light.py)."""
    defines = {
        **plot_defines(material, wavelengths, aa),
        "DIFFUSE": material.kd > 0.0 and max(material.albedo) > 0.0,
        "FRESNEL": material.f0 < 1.0,
    }
    if is_physical(material):
        # Applied last: the physical source wins.
        defines.update(_physical_defines(material, orders_read))
    if is_conductor(material):
        defines["SUBSTRATE_CONDUCTOR"] = True
    if has_film_weight(material):
        defines["FILM_WEIGHT"] = True
    if stack_film.is_stack(material):
        defines["STACK_PAIRS"] = material.film_stack_pairs
    if material.iridescence == "thin-film" and wavelengths == 0:  # the film's fast path
        defines["FILM_GAUSSIANS"] = visible.SENSITIVITY_GAUSSIANS
    if coat.has_coat(material):
        defines["COAT"] = True
    return defines


def is_conductor(material: Material) -> bool:
    return material.iridescence == "thin-film" and material.substrate == "conductor"


def has_film_weight(material: Material) -> bool:
    """A partial film: its base is compiled in only then (a whole film, the default, and
    every variant before the weight existed, compile as they did)."""
    return material.iridescence == "thin-film" and material.film_weight < 1.0


def uses_thickness_map(material: Material, preset: Preset) -> bool:
    return material.iridescence == "thin-film" and preset.thickness_map is not None


def uses_weight_map(material: Material, preset: Preset) -> bool:
    return material.iridescence == "thin-film" and preset.weight_map is not None


def uses_transmission(material: Material, preset: Preset) -> bool:
    # A metal under the film lets nothing through.
    return material.iridescence == "thin-film" and preset.transmission and not is_conductor(material)


def surface_defines(job: Job, preset: Preset, brute: bool = False) -> Defines:
    """The surface program's defines: the material's, then the scene's (no key in common);
    ``brute``: the brute-force reference, which samples a grating's whole lobe."""
    defines = material_defines(job.material, job.wavelengths, job.aa,
                               environment_light.orders_read(job, brute))
    defines["NORMAL_MAP"] = preset.normal_map is not None
    defines["TANGENT_CONCENTRIC"] = preset.tangents == "concentric"
    defines["LIGHT_COUNT"] = len(preset.lights)
    defines.update(heightfield.defines(preset))
    if uses_thickness_map(job.material, preset):
        defines["THICKNESS_MAP"] = True
    if uses_weight_map(job.material, preset):  # the weight per texel, times film_weight
        defines["FILM_WEIGHT_MAP"] = defines["FILM_WEIGHT"] = True
    if uses_transmission(job.material, preset):
        defines["TRANSMISSION"] = True
    return defines


def _cos_sin(theta: np.ndarray) -> list[tuple[float, float]]:
    return [(math.cos(a), math.sin(a)) for a in np.atleast_1d(theta)]


def material_uniforms(material: Material, wavelengths: int = 0,
                      shift: float = CENTRE) -> Uniforms:
    """Every uniform the material's programs may read (a variant ignores those it lacks)."""
    values: Uniforms = {
        "u_ex": material.ex,
        "u_ey": material.ey,
        "u_mu_f": material.mu_f,
        "u_alpha": material.alpha,
        "u_beta": material.beta,
        "u_ks": material.ks,
        "u_kd": material.kd,
        "u_albedo": tuple(material.albedo),
        "u_f0": material.f0,
        "u_coat_weight": material.coat_weight,
        "u_coat_f0": coat.coat_f0(material.coat_ior),
        "u_coat_exponent": coat.exponent_from_roughness(material.coat_roughness),
    }
    if wavelengths > 0:
        values.update(spectral_uniforms(material, wavelengths, shift))
    else:
        values["u_rotation"] = _cos_sin(np.array([0.0, material.theta1, material.theta2]))
    if is_physical(material):
        values.update(_physical_uniforms(material, wavelengths))
    return values


def spectral_uniforms(material: Material, wavelengths: int, shift: float) -> Uniforms:
    """Rotations and weights of ``wavelengths`` wavelengths at ``shift`` through their bins
    (spectrum.wavelength_shift): set again before each supersample."""
    theta = rotation_at(sample_wavelengths(wavelengths, shift), material.theta1, material.theta2)
    return {"u_spectral_rotation": _cos_sin(theta),
            "u_spectral_weight": [tuple(w) for w in rgb_weights(wavelengths, shift)]}


def _physical_uniforms(material: Material, wavelengths: int) -> Uniforms:
    values: Uniforms = {
        "u_film_ior": material.film_ior,
        "u_substrate_ior": material.substrate_ior,
        "u_film_thickness_min": material.film_thickness_min,
        "u_film_thickness_max": material.film_thickness_max,
        "u_film_weight": material.film_weight,
        "u_grating_pitch_nm": 1000.0 * material.grating_pitch,
        "u_grating_depth_nm": material.grating_depth,
    }
    if is_conductor(material):
        nk = np.atleast_1d(metals.substrate_for(material, wavelengths))
        values["u_substrate_nk"] = [(float(x.real), float(x.imag)) for x in nk]
    if stack_film.is_stack(material):
        values.update(_stack_uniforms(material, wavelengths))
    if wavelengths > 0:
        values["u_wavelength_nm"] = [float(x) for x in sample_wavelengths(wavelengths)]
    else:
        gaussians = visible.sensitivity_gaussians()
        values["u_film_sens_weight"] = [tuple(g) for g in gaussians[..., 0]]
        values["u_film_sens_centre"] = [tuple(g) for g in gaussians[..., 1]]
        values["u_film_sens_sigma"] = [tuple(g) for g in gaussians[..., 2]]
        values["u_visible_density"] = [tuple(row) for row in visible.density_table()[1]]
        values["u_visible_cumulative"] = visible.packed_cumulative_uniform()
        values["u_channel_nm"] = tuple(float(x) for x in grating.channel_wavelengths())
    return values


def _stack_uniforms(material: Material, wavelengths: int) -> Uniforms:
    """The spacer, and on the fast path the bins the stack is integrated over."""
    values: Uniforms = {"u_stack_spacer_ior": material.film_spacer_ior,
                        "u_stack_spacer_nm": material.film_spacer_thickness}
    if wavelengths == 0:
        bins = stack_film.STACK_BINS
        values["u_stack_bin_nm"] = [float(x) for x in sample_wavelengths(bins)]
        values["u_stack_bin_weight"] = [tuple(w) for w in rgb_weights(bins)]
        if is_conductor(material):
            nk = np.atleast_1d(stack_film.bin_substrate(material, 0))
            values["u_stack_bin_nk"] = [(float(x.real), float(x.imag)) for x in nk]
    return values
