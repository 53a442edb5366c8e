"""The resolve pass: accumulated linear samples to the display target.

Averages the samples (and each 2×2 block when the samples were drawn at twice the
size), applies exposure, the tone map and the sRGB encoding, and composes over the
preset's background (or leaves alpha for a transparent image).
"""

from __future__ import annotations

import moderngl

from opaline.gl import passes, uniforms
from opaline.gl.resources import Resources
from opaline.model.presets import Preset
from opaline.model.request import Job


def tonemap_defines(job: Job) -> dict[str, bool]:
    """The display encoding's defines, shared by the resolve and a direct (one-sample) draw."""
    return {"TONEMAP_REINHARD": job.tonemap == "reinhard", "TONEMAP_ACES": job.tonemap == "aces",
            "TONEMAP_NEUTRAL": job.tonemap == "neutral"}


class Resolver:
    def __init__(self, resources: Resources) -> None:
        self.resources = resources

    def resolve(self, job: Job, preset: Preset, source: moderngl.Texture,
                target: moderngl.Framebuffer, samples: passes.SamplePlan) -> None:
        defines = {**tonemap_defines(job), "TRANSPARENT": job.transparent,
                   "DOWNSAMPLE_2X": samples.factor == 2}
        program = self.resources.programs.get("resolve.glsl", defines)
        target.use()
        source.use(location=0)
        uniforms.apply(program, {"u_accum": 0, "u_inv_samples": 1.0 / samples.samples,
                                 "u_exposure": job.exposure,
                                 "u_background": tuple(preset.background),
                                 "u_height": target.size[1]})
        self.resources.fullscreen(program)
