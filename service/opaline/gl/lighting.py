"""The lights a job is drawn under: the preset's (key light moved as the job asks), or an
environment turned into K directional lights (``scene.environments``).

K is a quality knob like samples and wavelengths: the job's
``environment_lights`` if it sets one, else its tier's (chosen from the
time/error points in docs/accuracy.md). An environment replaces the preset's
lights; the preset's ambient term stays.
"""

from __future__ import annotations

from pathlib import Path

from opaline.model.camera import place_key_light
from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.scene.environments import environment_lights

# From bench/results/environment_lights.md (256², against K=256): each light costs about
# as much as the rest of the shading, and ΔE00 mean falls from 2-4 (K=8) through 1-2.3
# (16) and 0.6-1.6 (32) to 0.35-1 (64).
ENVIRONMENT_LIGHTS = {"draft": 8, "standard": 16, "high": 32, "reference": 64}


def environment_count(job: Job) -> int:
    return job.environment_lights or ENVIRONMENT_LIGHTS[job.quality]


def light_uniforms(job: Job, preset: Preset,
                   environments_dir: Path | None) -> dict[str, list[tuple]]:
    """``u_light_position`` (xyz and w: 1 point, 0 directional) and ``u_light_irradiance``."""
    if job.environment:
        direction, irradiance = environment_lights(
            job.environment, environment_count(job), job.environment_rotation or 0.0,
            1.0 if job.environment_intensity is None else job.environment_intensity,
            environments_dir)
        return {"u_light_position": [(*map(float, d), 0.0) for d in direction],
                "u_light_irradiance": [tuple(map(float, e)) for e in irradiance]}
    lights = place_key_light(preset.lights, preset.camera.target, job.light_azimuth,
                             job.light_elevation)
    return {"u_light_position": [(*light.position, 1.0 if light.type == "point" else 0.0)
                                 for light in lights],
            "u_light_irradiance": [tuple(light.irradiance) for light in lights]}
