"""Mesh density for the image size: thumbnails do not need the preset's full mesh.

llvmpipe pays per triangle (setup, binning) as well as per fragment, so a
256² image of the sphere's 16k triangles spent more time on triangles than on
shading (docs/speed.md). Up to ``THUMBNAIL`` pixels on the longer side, the
generator's density arguments are halved (a quarter of the triangles): at
256² a sphere segment still spans ~9 px and the silhouette is within 0.1 px
of the true circle, and normals and tangents are interpolated per fragment as
before. The wavy sheet, whose slope is computed per fragment (gl/heightfield.py),
goes to a quarter when its waves are gentle. Larger images draw the preset as written.
"""

from __future__ import annotations

from opaline.gl import heightfield
from opaline.model.presets import Generator, Preset
from opaline.scene import geometry

THUMBNAIL = 384
DENSITY_ARGS = ("segments", "resolution", "rings")
MIN_DENSITY = 4  # no generator argument is halved below this (the annulus's 4 rings stay)


def scene_for_size(preset: Preset, width: int, height: int) -> Preset:
    """``preset`` with its mesh at the density an image of this size needs."""
    if max(width, height) > THUMBNAIL:
        return preset
    full = geometry.arguments(preset.geometry.kind, preset.geometry.args)
    divisor = heightfield.thumbnail_divisor(preset)
    changed = {name: max(full[name] // divisor, MIN_DENSITY) for name in DENSITY_ARGS
               if isinstance(full.get(name), int) and full[name] > MIN_DENSITY}
    if not changed:
        return preset
    coarse = Generator(kind=preset.geometry.kind, **{**preset.geometry.args, **changed})
    return preset.model_copy(update={"geometry": coarse})
