"""How a job's environment lights it, decided once for the renderer and for admission.

The map is read for the rotation source and thin film, unless the request asks for
lights (``environment_lights``). Ashikhmin-Shirley lobes and films draw lobe samples.
The spectral multi-peak lobe is split (``model/envelope.py``): its envelope from the
map's irradiance, its bands from lobe samples, drawn only where the pixel's samples
resolve them. A spectral grating's orders are read where they leave
(``model/grating_environment.py``): sharp lobes about directions the lobe sampler does
not know. Median-cut lights stay for the RGB fast paths (wavelengths=0) of the grating,
whose orders are placed by wavelength, and of the multi-peak lobe, whose split's band
samples share a spectrum.
"""

from __future__ import annotations

import math

from opaline.model.envelope import bands_resolved
from opaline.model.request import Job
from opaline.scene.bright import MAX_LIGHTS

# Fewer wavelengths a band sample drew the channels from unbalanced sums of the colour
# matching weights (which go negative): at 6 samples of 16 wavelengths, colour noise
# took the sphere's FLIP from 0.127 (4 samples) to 0.19.
WAVELENGTHS_PER_SAMPLE = 4
GRATING_PIECES_PER_LIGHT = 10


def reads_map(job: Job) -> bool:
    material = job.material
    from_map = material.iridescence == "thin-film" or (
        material.iridescence == "rotation" and material.mdf == "ashikhmin") or (
        job.wavelengths > 0 and material.iridescence in ("rotation", "grating"))
    return job.environment is not None and job.environment_lights is None and from_map


def reads_orders(job: Job) -> bool:
    """Whether the map is read along the curve a grating's orders leave by, in pieces
    (glsl/lib/environment_grating.glsl), instead of through lobe samples."""
    return reads_map(job) and job.material.iridescence == "grating"


def splits_lobe(job: Job) -> bool:
    """Whether the lobe is the multi-peak one read as envelope and bands (spectral: a
    pass's band samples share the wavelengths)."""
    material = job.material
    return reads_map(job) and material.iridescence == "rotation" and material.mdf == "multipeak"


def band_samples(job: Job, per_pass: int) -> int:
    """A pass's lobe samples for the multi-peak bands, each wavelength read by one of
    them: none where one sample of each wavelength a pass (job.samples over the pixel)
    cannot resolve them. In one pass, at most one for every ``WAVELENGTHS_PER_SAMPLE``
    wavelengths, which spreads a wavelength's reads over directions; over several passes,
    one a pass carrying every wavelength, which costs the same spectral evaluation and
    keeps each wavelength's samples a contiguous run of the pixel's sequence (sample i of
    every pass is every N-th point of it, bunched in radius: r² within 0.14 at N = 4)."""
    material = job.material
    if not bands_resolved(material.mu_f, material.alpha, material.beta, job.samples):
        return 0
    if job.samples > 1:
        return 1
    return max(1, min(per_pass, job.wavelengths // WAVELENGTHS_PER_SAMPLE))


def light_equivalents(job: Job) -> int:
    """What one sample of the job shades, counted in lights: K median-cut lights, or a
    sample's share of the lobe samples plus the bright features split off the map (a
    lobe sample costs at most about one light, the reflectance evaluated once for it,
    and less where the film or the rotation's channels are shared; the multi-peak
    bands' samples of a pass, one spectral evaluation together)."""
    if not reads_map(job):
        return job.environment_count
    per_pass = math.ceil(job.environment_sample_count / job.samples)
    if reads_orders(job):
        # A piece of the orders' curve (two more than asked, at most) costs about a tenth
        # of a light that evaluates every order (bench/speed_env.py).
        return math.ceil((per_pass + 2) / GRATING_PIECES_PER_LIGHT) + MAX_LIGHTS
    if splits_lobe(job):
        return min(1, band_samples(job, per_pass)) + MAX_LIGHTS
    return per_pass + MAX_LIGHTS
