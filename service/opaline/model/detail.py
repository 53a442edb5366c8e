"""Mesh density for the image size: thumbnails do not need the preset's full mesh.

llvmpipe pays per triangle (setup, binning) as well as per fragment, so a
256² image of the sphere's 16k triangles spent more time on triangles than on
shading (docs/speed.md). Up to ``THUMBNAIL`` pixels on the longer side, the
generator's density arguments are halved (a quarter of the triangles): at
256² a sphere segment still spans ~9 px and the silhouette is within 0.1 px
of the true circle, and normals and tangents are interpolated per fragment as
before. The wavy sheet, whose slope is computed per fragment (gl/heightfield.py),
goes to a quarter when its waves are gentle. Larger images draw the preset as written.

NumPy only (no GL): it decides which mesh the renderer uploads, so it lives with the
preset it rewrites, under the renderer's layer.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from opaline.model.presets import Generator, Preset
from opaline.scene import geometry
from opaline.scene.waves import check_waves

THUMBNAIL = 384
DENSITY_ARGS = ("segments", "resolution", "rings")
MIN_DENSITY = 4  # no generator argument is halved below this (the annulus's 4 rings stay)

MAX_WAVES = 8  # more (a preset may list any number) keep the mesh's normals
# A quarter of the density (a sixteenth of the triangles; every other mesh is halved)
# where the waves are gentle: slopes summing to at most GENTLE_SLOPE, and the shortest
# wave spanning at least CELLS_PER_WAVE cells of the coarse grid. The oil presets'
# swells (slopes 0.13 in all, 10 cells) stay within FLIP 0.005 of the full mesh; a wave
# of slope 1.7 moved 0.02 there, against 0.005 at half the density.
GENTLE_SLOPE = 0.2
CELLS_PER_WAVE = 8


def analytic_sheet(preset: Preset) -> tuple[dict[str, Any], np.ndarray] | None:
    """The wavy sheet's arguments (defaults filled in) and its waves, if its slope is
    computed per fragment (gl/heightfield.py): at most ``MAX_WAVES`` waves."""
    if preset.geometry.kind != "wavy":
        return None
    args = geometry.arguments("wavy", preset.geometry.args)
    waves = check_waves(args["waves"])
    return (args, waves) if 1 <= len(waves) <= MAX_WAVES else None


def thumbnail_divisor(preset: Preset) -> int:
    """By how much a thumbnail may divide this preset's density arguments (2 or 4)."""
    sheet = analytic_sheet(preset)
    if sheet is None:
        return 2
    args, waves = sheet
    cell = float(args["size"]) / max(int(args["resolution"]) // 4 - 1, 1)
    amplitude, wavelength = np.abs(waves[:, 0]), waves[:, 1]
    gentle = float((amplitude * 2.0 * np.pi / wavelength).sum()) <= GENTLE_SLOPE
    resolved = float(wavelength.min()) >= CELLS_PER_WAVE * cell
    return 4 if gentle and resolved else 2


def scene_for_size(preset: Preset, width: int, height: int) -> Preset:
    """``preset`` with its mesh at the density an image of this size needs."""
    if max(width, height) > THUMBNAIL:
        return preset
    full = geometry.arguments(preset.geometry.kind, preset.geometry.args)
    divisor = thumbnail_divisor(preset)
    changed = {name: max(full[name] // divisor, MIN_DENSITY) for name in DENSITY_ARGS
               if isinstance(full.get(name), int) and full[name] > MIN_DENSITY}
    if not changed:
        return preset
    coarse = Generator(kind=preset.geometry.kind, **{**preset.geometry.args, **changed})
    return preset.model_copy(update={"geometry": coarse})
