"""How a job's environment lights it, decided once for the renderer and for admission.

The map is read by lobe samples when the lobe is Ashikhmin-Shirley's (the rotation
source's ``ashikhmin`` MDF, thin film), unless the request asks for lights
(``environment_lights``). The multi-peak lobe spans the hemisphere and a grating's
orders are sharp lobes about directions the sampler does not know: for those,
median-cut lights measured closer to the brute-force reference at every tier
(bench/environment_accuracy.py, docs/accuracy.md).
"""

from __future__ import annotations

import math

from opaline.model.request import Job
from opaline.scene.bright import MAX_LIGHTS


def reads_map(job: Job) -> bool:
    material = job.material
    lobe_sampled = material.iridescence == "thin-film" or (
        material.iridescence == "rotation" and material.mdf == "ashikhmin")
    return job.environment is not None and job.environment_lights is None and lobe_sampled


def light_equivalents(job: Job) -> int:
    """What one sample of the job shades, counted in lights: K median-cut lights, or a
    sample's share of the lobe samples plus the bright features split off the map (each
    lobe sample costs about one light: the reflectance is evaluated once for each)."""
    if not reads_map(job):
        return job.environment_count
    return math.ceil(job.environment_sample_count / job.samples) + MAX_LIGHTS
