"""What the thin film needs beyond its defines and uniforms (gl/material_program.py):
its thickness field as a texture, and the backdrop a transmitting film lets through."""

from __future__ import annotations

from collections.abc import Sequence

import moderngl
import numpy as np


def thickness_texture(ctx: moderngl.Context, field: np.ndarray | None,
                      wraps_v: bool = True) -> moderngl.Texture | None:
    """A [0, 1] field over uv (a film's thickness or weight) as a mipmapped one-channel
    float texture that tiles in u, and in v where the surface's v wraps (``wraps_v``)."""
    if field is None:
        return None
    height, width = field.shape
    # Rows flipped: the field's row 0 is v = 1 (image convention), GL's is v = 0.
    data = np.ascontiguousarray(field[::-1].astype("f4"))
    texture = ctx.texture((width, height), 1, data.tobytes(), dtype="f4")
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x, texture.repeat_y = True, wraps_v
    return texture


def backdrop_radiance(background: Sequence[float], tonemap: str, exposure: float,
                      space: str = "srgb") -> tuple[float, ...]:
    """The linear sRGB radiance that displays as the preset's background colour after
    exposure, tone map and the output's encoding: what a film that transmits everything
    lets through."""
    from opaline.model import color_space
    from opaline.model.display import tonemap_inverse

    shown = color_space.display_background(background, space)
    y = np.clip(color_space.decode(shown, space), 0.0, 0.999)
    x = np.linalg.solve(color_space.from_srgb(space), tonemap_inverse(y, tonemap))
    return tuple(float(v) for v in x / exposure)
