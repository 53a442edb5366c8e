"""The resolve pass: accumulated linear samples to the display target (a mixin of Renderer).

Averages the samples (and each 2×2 block when the samples were drawn at twice the
size), applies exposure, the tone map and the sRGB encoding, and composes over the
preset's background (or leaves alpha for a transparent image).
"""

from __future__ import annotations

from typing import Any

import moderngl

from opaline.gl import passes, uniforms
from opaline.model.presets import Preset
from opaline.model.request import Job


class Resolve:
    programs: Any

    def fullscreen(self, program: moderngl.Program) -> None: ...

    def _resolve(self, job: Job, preset: Preset, source: moderngl.Texture,
                 target: moderngl.Framebuffer, samples: passes.SamplePlan) -> None:
        defines = {**self.tonemap_defines(job), "TRANSPARENT": job.transparent,
                   "DOWNSAMPLE_2X": samples.factor == 2}
        program = self.programs.get("resolve.glsl", defines)
        target.use()
        source.use(location=0)
        uniforms.apply(program, {"u_accum": 0, "u_inv_samples": 1.0 / samples.samples,
                                 "u_exposure": job.exposure,
                                 "u_background": tuple(preset.background),
                                 "u_height": target.size[1]})
        self.fullscreen(program)

    @staticmethod
    def tonemap_defines(job: Job) -> dict[str, bool]:
        return {"TONEMAP_REINHARD": job.tonemap == "reinhard", "TONEMAP_ACES": job.tonemap == "aces"}
