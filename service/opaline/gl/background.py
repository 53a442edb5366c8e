"""The environment as the background (``environment_background``): its map drawn behind
the object in every sample, before the surface pass, with the lights' rotation and scale.

The maps are uploaded once per environment with their mip chain and kept (a few;
128×256 or 256×512 RGB float for the built-in ones), released with the renderer.
``environment_blur`` reads a coarser mip, trilinear between levels: at 1 the level
whose texels span ``BLUR_DEGREES`` (counted from the map's own texel, so a blur is
the same angle on any map), in between a span growing geometrically from the map's
texel; 0 reads the sharp map as before.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path

import moderngl
import numpy as np

from opaline.gl import texture_units, uniforms
from opaline.gl.shaders import ProgramCache
from opaline.model import irradiance
from opaline.model.request import Job
from opaline.scene.environments import resolve_map

KEPT = 4
BLUR_DEGREES = 30.0  # a texel's span at environment_blur = 1: a soft wash, no features


class Backgrounds:
    def __init__(self, ctx: moderngl.Context, fullscreen: Callable[[moderngl.Program], None],
                 environments_dir: Path | None):
        self.ctx = ctx
        self.fullscreen = fullscreen
        self.environments_dir = environments_dir
        self._maps: OrderedDict[str, moderngl.Texture] = OrderedDict()
        self._irradiance: dict[str, np.ndarray] = {}

    def texture(self, name: str) -> moderngl.Texture:
        found = self._maps.get(name)
        if found is None:
            radiance = resolve_map(name, self.environments_dir)
            height, width = radiance.shape[:2]
            # Rows flipped: the map's row 0 is the zenith, GL's row 0 is v = 0 (the nadir).
            data = np.ascontiguousarray(radiance[::-1], dtype="f4")
            found = self.ctx.texture((width, height), 3, data.tobytes(), dtype="f4")
            # The one place the map's sampling is set: environment light (filtered
            # importance sampling) and the backdrop's blur read this chain.
            found.build_mipmaps()
            found.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            found.repeat_x, found.repeat_y = True, False
            self._maps[name] = found
            self._irradiance[name] = irradiance.coefficients(radiance)
            while len(self._maps) > KEPT:
                forgotten, texture = self._maps.popitem(last=False)
                texture.release()
                self._irradiance.pop(forgotten, None)
        self._maps.move_to_end(name)
        return found

    def irradiance(self, name: str) -> np.ndarray:
        """The map's irradiance coefficients (model/irradiance.py), made with its texture."""
        self.texture(name)
        return self._irradiance[name]

    def prepare(self, programs: ProgramCache, job: Job, view_proj: np.ndarray,
                size: tuple[int, int]) -> Callable[[tuple[float, float]], None] | None:
        """A draw call for one sample (given its NDC jitter), or None when not asked for."""
        if not (job.environment and job.environment_background):
            return None
        program = programs.get("environment.glsl")
        texture = self.texture(job.environment)
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

    def release(self) -> None:
        for texture in self._maps.values():
            texture.release()
        self._maps.clear()
        self._irradiance.clear()


def blur_level(blur: float, height: int) -> float:
    """The mip level for ``blur`` on a map ``height`` rows tall (a row spans 180° /
    height): 0 at no blur, the level whose texels span ``BLUR_DEGREES`` at 1, linear in
    level (so geometric in angle) between."""
    if blur <= 0.0:
        return 0.0
    return blur * max(0.0, math.log2(BLUR_DEGREES * height / 180.0))
