"""The environment as the background (``environment_background``): its map drawn behind
the object in every sample, before the surface pass, with the lights' rotation and scale.

The maps are the renderer's ``EnvironmentMaps`` (uploaded once, with their mip chain).
``environment_blur`` reads a coarser mip, trilinear between levels: at 1 the level
whose texels span ``BLUR_DEGREES`` (counted from the map's own texel, so a blur is
the same angle on any map), in between a span growing geometrically from the map's
texel; 0 reads the sharp map as before.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import moderngl
import numpy as np

from opaline.gl import texture_units, uniforms
from opaline.gl.environment_maps import EnvironmentMaps
from opaline.gl.shaders import ProgramCache
from opaline.model.request import Job

BLUR_DEGREES = 30.0  # a texel's span at environment_blur = 1: a soft wash, no features


class Backgrounds:
    def __init__(self, ctx: moderngl.Context, fullscreen: Callable[[moderngl.Program], None],
                 maps: EnvironmentMaps):
        self.ctx = ctx
        self.fullscreen = fullscreen
        self.maps = maps

    def prepare(self, programs: ProgramCache, job: Job, view_proj: np.ndarray,
                size: tuple[int, int]) -> Callable[[tuple[float, float]], None] | None:
        """A draw call for one sample (given its NDC jitter), or None when not asked for."""
        if not (job.environment and job.environment_background):
            return None
        program = programs.get("environment.glsl")
        texture = self.maps.get(job.environment).texture
        intensity = 1.0 if job.environment_intensity is None else job.environment_intensity
        uniforms.apply(program, {
            "u_environment": texture_units.ENVIRONMENT, "u_size": (float(size[0]), float(size[1])),
            "u_inv_view_proj": np.linalg.inv(view_proj).astype("f4"),
            "u_rotation": math.radians(job.environment_rotation or 0.0),
            "u_intensity": intensity, "u_lod": blur_level(job.environment_blur or 0.0,
                                                          texture.height)})

        def draw(jitter: tuple[float, float]) -> None:
            texture.use(location=texture_units.ENVIRONMENT)
            program["u_jitter"] = jitter
            self.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
            self.fullscreen(program)

        return draw


def blur_level(blur: float, height: int) -> float:
    """The mip level for ``blur`` on a map ``height`` rows tall (a row spans 180° /
    height): 0 at no blur, the level whose texels span ``BLUR_DEGREES`` at 1, linear in
    level (so geometric in angle) between."""
    if blur <= 0.0:
        return 0.0
    return blur * max(0.0, math.log2(BLUR_DEGREES * height / 180.0))
