"""The lights a job is drawn under: the preset's (key light moved as the job asks), or an
environment turned into K directional lights (``scene.environments``).

K is a quality knob like samples and wavelengths: the job's
``environment_lights`` if it sets one, else its tier's (``Job.environment_count``).
An environment replaces the preset's lights and its ambient term (the lights carry all of
the map, its diffuse part too).
"""

from __future__ import annotations

from opaline.gl.environment_maps import EnvironmentMaps
from opaline.gl.uniforms import Vector
from opaline.model.camera import place_key_light
from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.scene.environments import environment_lights


def light_uniforms(job: Job, preset: Preset, maps: EnvironmentMaps) -> dict[str, list[Vector]]:
    """``u_light_position`` (xyz and w: 1 point, 0 directional) and ``u_light_irradiance``."""
    if job.environment:
        direction, irradiance = environment_lights(
            job.environment, job.environment_count, job.environment_rotation or 0.0,
            1.0 if job.environment_intensity is None else job.environment_intensity,
            maps.environments_dir, maps.paths)
        return {"u_light_position": [(*map(float, d), 0.0) for d in direction],
                "u_light_irradiance": [tuple(map(float, e)) for e in irradiance]}
    lights = place_key_light(preset.lights, preset.camera.target, job.light_azimuth,
                             job.light_elevation)
    return {"u_light_position": [(*light.position, 1.0 if light.type == "point" else 0.0)
                                 for light in lights],
            "u_light_irradiance": [tuple(light.irradiance) for light in lights]}
