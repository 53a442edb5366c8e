"""Environment light from its map (``glsl/lib/environment_light.glsl``): what the surface
program compiles and is fed when a job's environment is read as a texture, not as lights.

A job reads the map unless it asks for lights (``environment_lights``) or draws a
grating, whose diffraction orders are sharp lobes about directions the lobe sampler
does not know (docs/design.md §4.6): those keep median-cut lights (``gl/lighting.py``).
The pixel's ``environment_samples`` are shared among the passes (and the 2×2 grid of
a supersampled pass); each pass continues the pixel's sequence where the last stopped.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from opaline.gl import texture_units
from opaline.gl.passes import SamplePlan
from opaline.gl.uniforms import Uniforms
from opaline.model.request import Job


def reads_map(job: Job) -> bool:
    return (job.environment is not None and job.environment_lights is None
            and job.material.iridescence != "grating")


def samples_per_pass(job: Job, samples: SamplePlan) -> int:
    per_pass_pixels = samples.passes * samples.factor * samples.factor
    return max(1, -(-job.environment_sample_count // per_pass_pixels))


def defines(job: Job, samples: SamplePlan, brute: bool = False) -> dict[str, int | bool]:
    return {"ENVIRONMENT_MAP": True, "ENV_SAMPLES": samples_per_pass(job, samples),
            "ENV_BRUTE": brute, "ENV_BACKDROP": bool(job.environment_background),
            "LIGHT_COUNT": False}


def uniforms(job: Job, samples: SamplePlan, texture: moderngl.Texture,
             sh: np.ndarray) -> Uniforms:
    width, height = texture.size
    per_pixel = samples_per_pass(job, samples) * samples.passes * samples.factor ** 2
    material = job.material
    return {
        "u_env_map": texture_units.ENVIRONMENT,
        "u_env_rotation": math.radians(job.environment_rotation or 0.0),
        "u_env_intensity": 1.0 if job.environment_intensity is None else job.environment_intensity,
        "u_env_size": (float(width), float(height)),
        "u_env_max_lod": float(math.floor(math.log2(max(width, height)))),
        "u_env_total": float(per_pixel),
        "u_env_pass": 0,
        "u_env_lobe_rotation": [(math.cos(a), math.sin(a))
                                for a in (0.0, material.theta1, material.theta2)],
        "u_env_sh": [tuple(map(float, c)) for c in sh],
    }
