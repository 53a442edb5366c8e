"""Environments on the GPU: each map uploaded once with its mip chain, with what lighting
needs besides (its irradiance coefficients, its bright features as lights), kept for a
few environments and released with the renderer.

The map uploaded is the one ``scene.bright`` leaves: a sun's texels capped at the
threshold, their excess carried by lights. The background shows that map too; a
capped sun is still far past white after any tone map.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

import moderngl
import numpy as np

from opaline.model import irradiance
from opaline.scene.bright import split_bright
from opaline.scene.environments import map_identity, resolve_map

KEPT = 4


@dataclass(frozen=True)
class EnvironmentMap:
    texture: moderngl.Texture
    irradiance: np.ndarray  # (9, 3) of the uploaded map (model/irradiance.py)
    light_directions: np.ndarray  # (K, 3), in the map's frame, toward the light
    light_irradiance: np.ndarray  # (K, 3)


class EnvironmentMaps:
    def __init__(self, ctx: moderngl.Context, environments_dir: Path | None,
                 paths: bool = False) -> None:
        self.ctx = ctx
        self.environments_dir = environments_dir
        self.paths = paths  # a map may be named by its path (scene.environments.check_name)
        self._maps: OrderedDict[tuple[object, ...], EnvironmentMap] = OrderedDict()

    def get(self, name: str) -> EnvironmentMap:
        key = map_identity(name, self.environments_dir, self.paths)  # a file replaced is read again
        found = self._maps.get(key)
        if found is None:
            found = self._upload(name)
            self._maps[key] = found
            while len(self._maps) > KEPT:
                self._maps.popitem(last=False)[1].texture.release()
        self._maps.move_to_end(key)
        return found

    def _upload(self, name: str) -> EnvironmentMap:
        radiance, directions, lights = split_bright(
            resolve_map(name, self.environments_dir, self.paths))
        height, width = radiance.shape[:2]
        # Rows flipped: the map's row 0 is the zenith, GL's row 0 is v = 0 (the nadir).
        # RGBA, the fourth channel unread: llvmpipe fetches 16-byte texels faster than
        # 12-byte ones (the studio at standard, 9 lobe samples: ~10 % of the render).
        rgba = np.concatenate([radiance[::-1], np.ones((height, width, 1), radiance.dtype)], 2)
        texture = self.ctx.texture((width, height), 4,
                                   np.ascontiguousarray(rgba, dtype="f4").tobytes(), dtype="f4")
        # The one place the map's sampling is set: environment light (filtered
        # importance sampling) and the backdrop's blur read this chain. One level a read:
        # the surface picks a read's level at random with trilinear's weights (env_level
        # in glsl/lib/environment_light.glsl), the backdrop mixes two; a trilinear read
        # cost llvmpipe as much as the rest of a lobe sample.
        texture.build_mipmaps()
        texture.filter = (moderngl.LINEAR_MIPMAP_NEAREST, moderngl.LINEAR)
        texture.repeat_x, texture.repeat_y = True, False
        return EnvironmentMap(texture, irradiance.coefficients(radiance), directions, lights)

    def release(self) -> None:
        for environment in self._maps.values():
            environment.texture.release()
        self._maps.clear()
