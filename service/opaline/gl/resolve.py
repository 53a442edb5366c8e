"""The resolve pass: accumulated linear samples to the display target.

Averages the samples (and each 2×2 block when the samples were drawn at twice the
size), applies exposure, takes the colour to the output's primaries and gamut, tone maps
and encodes it with the output's transfer curve, and composes over the preset's
background (or leaves alpha for a transparent image).
"""

from __future__ import annotations

import moderngl
import numpy as np

from opaline.gl import passes, uniforms
from opaline.gl.resources import Resources
from opaline.model import color_space
from opaline.model.presets import Preset
from opaline.model.request import Job


def display_defines(job: Job) -> dict[str, bool]:
    """The display encoding's defines, shared by the resolve and a direct (one-sample) draw."""
    return {"TONEMAP_REINHARD": job.tonemap == "reinhard", "TONEMAP_ACES": job.tonemap == "aces",
            "TONEMAP_NEUTRAL": job.tonemap == "neutral",
            "TRANSFER_BT709": job.color_space == "rec2020"}


def display_uniforms(job: Job) -> uniforms.Uniforms:
    """The output's primaries and luminance weights (glsl/lib/display.glsl)."""
    # GLSL reads a mat3 column by column: the transpose's rows are the matrix's columns.
    matrix = np.ascontiguousarray(color_space.from_srgb(job.color_space).T)
    return {"u_output_from_srgb": matrix,
            "u_output_luminance": tuple(float(v) for v in color_space.luminance(job.color_space))}


class Resolver:
    def __init__(self, resources: Resources) -> None:
        self.resources = resources

    def resolve(self, job: Job, preset: Preset, source: moderngl.Texture,
                target: moderngl.Framebuffer, samples: passes.SamplePlan) -> None:
        defines = {**display_defines(job), "TRANSPARENT": job.transparent,
                   "DOWNSAMPLE_2X": samples.factor == 2}
        program = self.resources.programs.get("resolve.glsl", defines)
        target.use()
        source.use(location=0)
        background = color_space.display_background(preset.background, job.color_space)
        uniforms.apply(program, {"u_accum": 0, "u_inv_samples": 1.0 / samples.samples,
                                 "u_exposure": job.exposure,
                                 "u_background": tuple(float(v) for v in background),
                                 "u_height": target.size[1], **display_uniforms(job)})
        self.resources.fullscreen(program)
