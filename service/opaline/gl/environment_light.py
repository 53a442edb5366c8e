"""Environment light from its map (``glsl/lib/environment_light.glsl``): what the surface
program compiles and is fed when a job's environment is read as a texture, not as lights.

Which jobs read the map is ``model.environment_light.reads_map``'s decision; the others
have median-cut lights (``gl/lighting.py``).
The pixel's ``environment_samples`` are shared among the passes (and the 2×2 grid of
a supersampled pass); each pass continues the pixel's sequence where the last stopped.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from opaline.gl import texture_units
from opaline.gl.environment_maps import EnvironmentMap
from opaline.gl.passes import SamplePlan
from opaline.gl.uniforms import Uniforms
from opaline.model import grating, visible
from opaline.model.coat import exponent_from_roughness, has_coat
from opaline.model.envelope import band_mean, cell_side
from opaline.model.environment_light import band_samples, reads_orders, splits_lobe
from opaline.model.params import Material
from opaline.model.request import Job
from opaline.model.stack_film import is_stack

# From this many samples a pixel, the film is evaluated at each sample's own v·h, and the
# rotation source's map samples take its spectral colour; below (draft's 2 and 3,
# standard's 4 and 6), the film once a pixel at the v·h its light came from, and the
# paper's three channels (glsl/lib/environment_light.glsl, docs/design.md §4.5). Against
# the brute-force reference (bench/environment_accuracy.py, studio, 128², standard) the
# film once a pixel measured FLIP 0.020 on a glossy film and 0.030-0.046 on broad ones,
# at every sample 0.017-0.029 at two to three times the time; the three channels 0.106
# against the spectrum's 0.106 at 6 samples, at half the time.
FILM_PER_SAMPLE_FROM = 48
# A lobe sample reads the level whose texel spans its share 1/(N·pdf), less this many
# levels (env_lod_of in glsl/lib/environment_light.glsl).
LOD_BIAS = 2.0


def orders_read(job: Job, brute: bool = False) -> bool:
    """Whether this draw reads a grating's orders from the map: the job's choice
    (model.environment_light.reads_orders), never in the brute-force reference, which
    samples the whole lobe."""
    return reads_orders(job) and not brute


def samples_per_pass(job: Job, samples: SamplePlan, brute: bool = False) -> int:
    """A pass's lobe samples; the multi-peak lobe's band samples where it is split, none
    where a grating's orders are read (never in the brute-force reference, which samples
    the whole lobe)."""
    if orders_read(job, brute):
        return 0
    per_pass = _per_pass(job, samples)
    return band_samples(job, per_pass) if splits_lobe(job) and not brute else per_pass


def _per_pass(job: Job, samples: SamplePlan) -> int:
    return max(1, -(-job.environment_sample_count // samples.pass_pixels))


def grating_reads(job: Job, samples: SamplePlan, brute: bool = False) -> int:
    """A pass's reads along the curve a grating's orders leave by (0: not read so)."""
    return _per_pass(job, samples) if orders_read(job, brute) else 0


def coat_reads_per_pass(job: Job, samples: SamplePlan, environment: EnvironmentMap,
                        brute: bool = False) -> int:
    """A pass's reads of a clear coat's lobe (glsl/lib/environment_coat.glsl): one where
    one a pass already reads level 0 at the lobe's peak (a sharp coat: more would read the
    same texels), else as many as the material's own lobe takes. A rough coat of a high
    index read once a pass was speckled with the soft boxes (`coated-paint` at
    coat_roughness 1, coat_ior 3, studio, standard: FLIP 0.095, grain 0.062 against the
    reference's 0.007; at the pass's four, pooled, 0.057 and 0.021)."""
    if brute:
        return samples_per_pass(job, samples, brute=True)
    exponent = exponent_from_roughness(job.material.coat_roughness)
    # 1/(N·pdf) for one read a pass, pdf = (e + 1)/(8π) at the peak
    share = 8.0 * math.pi / ((exponent + 1.0) * samples.pass_pixels)
    width, height = environment.texture.size
    texel = 2.0 * math.pi * math.pi / (width * height)  # at the horizon, the largest
    sharp = 0.5 * math.log2(share / texel) - LOD_BIAS <= 0.0
    return 1 if sharp else _per_pass(job, samples)


def _coat_defines(job: Job, samples: SamplePlan, environment: EnvironmentMap,
                  brute: bool) -> dict[str, int | bool]:
    if not has_coat(job.material):
        return {}
    reads = coat_reads_per_pass(job, samples, environment, brute)
    per_pixel = reads * samples.pass_pixels
    return {"COAT_SAMPLES": reads,
            "COAT_QUAD_MEAN": not brute and reads > 1 and per_pixel < FILM_PER_SAMPLE_FROM}


def defines(job: Job, samples: SamplePlan, environment: EnvironmentMap,
            brute: bool = False) -> dict[str, int | bool]:
    lights = len(environment.light_directions)
    material = job.material
    # Few samples a pixel: the film's colour and the rotation's channels are shared.
    shared = not brute and job.environment_sample_count < FILM_PER_SAMPLE_FROM
    # A stack's colour costs 2N layers a wavelength: once a pixel at any sample count
    # (bragg-mirror's 128² ground truth: an estimated 33 min with it at every sample, 1.3 once).
    film_shared = shared or (not brute and is_stack(material))
    # The rotation source's three lobes at few samples: the paper's channels at its map
    # samples (spectral ones).
    three_lobes = material.iridescence == "rotation" and material.mdf == "ashikhmin" and shared
    film_per_pixel = material.iridescence == "thin-film" and film_shared
    return {"ENVIRONMENT_MAP": True, "ENV_SAMPLES": samples_per_pass(job, samples, brute),
            "ENV_BRUTE": brute, "ENV_BACKDROP": bool(job.environment_background),
            # The brute-force reference samples the whole multi-peak lobe at every wavelength.
            "ENV_ENVELOPE": splits_lobe(job) and not brute,
            "ENV_GRATING_ORDERS": orders_read(job, brute),
            "ENV_GRATING_READS": grating_reads(job, samples, brute) or False,
            "FILM_PER_PIXEL": film_per_pixel,
            "ENV_RGB_LOBES": three_lobes and job.wavelengths > 0,
            # A few A-S lobe samples a pixel (a film's lobe is always A-S), the rotation's
            # or a film's, pooled over the pixel's 2×2 quad where the lobe is wider than a
            # pixel's step (a film: its colour at the pixel's own v·h times its own light,
            # then the quad's mean). A grating's reads and the multi-peak bands are not:
            # pooling left the gratings' error where it was (docs/design.md §4.5).
            "ENV_QUAD_MEAN": shared and (three_lobes or film_per_pixel),
            "LIGHT_COUNT": lights if lights else False,
            **_coat_defines(job, samples, environment, brute),
            # A lobe sample's h is drawn anew in each pixel, so the pixel filter's screen
            # derivative of the multi-peak phase at it means nothing: the brute-force
            # reference reads the bands unfiltered (the split lobe filters its own).
            **({"AA_ANALYTIC": False} if brute and material.mdf == "multipeak" else {})}


def map_uniforms(texture: moderngl.Texture, irradiance: np.ndarray) -> Uniforms:
    """What the shader reads of the map itself (the surface's and the lobe probe's)."""
    width, height = texture.size
    return {"u_env_map": texture_units.ENVIRONMENT,
            "u_env_size": (float(width), float(height)),
            "u_env_max_lod": float(math.floor(math.log2(max(width, height)))),
            "u_env_sh": [tuple(map(float, c)) for c in irradiance]}


def grating_uniforms() -> Uniforms:
    """The spectrum in closed form, which a grating's orders and lights are weighted by
    under an environment read from its map, whatever the job's wavelengths."""
    return {"u_visible_density": [tuple(row) for row in visible.density_table()[1]],
            "u_visible_cumulative": visible.packed_cumulative_uniform(),
            "u_channel_nm": tuple(float(x) for x in grating.channel_wavelengths())}


def lobe_rotations(material: Material) -> list[tuple[float, float]]:
    """(cos, sin) of the three lobes the rotation source samples: 0, theta1, theta2."""
    return [(math.cos(a), math.sin(a)) for a in (0.0, material.theta1, material.theta2)]


def uniforms(job: Job, samples: SamplePlan, environment: EnvironmentMap,
             brute: bool = False) -> Uniforms:
    per_pixel = samples_per_pass(job, samples, brute) * samples.pass_pixels
    material = job.material
    rotation = math.radians(job.environment_rotation or 0.0)
    intensity = 1.0 if job.environment_intensity is None else job.environment_intensity
    values: Uniforms = {
        **map_uniforms(environment.texture, environment.irradiance),
        "u_env_rotation": rotation,
        "u_env_intensity": intensity,
        "u_env_total": float(per_pixel),
        "u_env_coat_total": float(coat_reads_per_pass(job, samples, environment, brute)
                                  * samples.pass_pixels),
        "u_env_pass": 0,
        "u_env_lobe_rotation": lobe_rotations(material),
    }
    if splits_lobe(job):  # the bands' filtered mean at the cell a wavelength's samples span
        values["u_env_band_mean"] = band_mean(material.mu_f, material.alpha, material.beta,
                                              cell_side(job.samples))
    if orders_read(job, brute):
        values.update(grating_uniforms())
    if len(environment.light_directions):
        # The map turns by +rotation about +y (atan2(z, x) grows): its lights with it.
        c, s = math.cos(rotation), math.sin(rotation)
        turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        values["u_light_position"] = [(*map(float, d), 0.0)
                                      for d in environment.light_directions @ turn]
        values["u_light_irradiance"] = [tuple(map(float, e * intensity))
                                        for e in environment.light_irradiance]
    return values
