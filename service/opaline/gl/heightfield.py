"""The wavy sheet's slope evaluated per fragment (glsl/lib/waves.glsl): its define, its
uniforms, and the mesh density that is then enough.

With vertex normals, a thumbnail of an oil slick needed the mesh fine: its bands follow
the normal closely, and at half the preset's density they had already moved (FLIP 0.018
against the full mesh at 256²). With the slope computed where it is shaded, the mesh
only carries positions, which a gentle swell barely lifts off a plane: a thumbnail may
then draw a quarter of the density. Steep or short waves (a user's preset may have any)
still need the mesh for their heights, occlusion and outline, and keep the half.
"""

from __future__ import annotations

import numpy as np

from opaline.model.presets import Preset
from opaline.scene import geometry
from opaline.scene.waves import check_waves

MAX_WAVES = 8  # more (a preset may list any number) keep the mesh's normals
# A quarter of the density (a sixteenth of the triangles; gl/detail.py halves every
# other mesh) where the waves are gentle: slopes summing to at most GENTLE_SLOPE, and
# the shortest wave spanning at least CELLS_PER_WAVE cells of the coarse grid. The
# oil presets' swells (slopes 0.13 in all, 10 cells) stay within FLIP 0.005 of the full
# mesh; a wave of slope 1.7 moved 0.02 there, against 0.005 at half the density.
GENTLE_SLOPE = 0.2
CELLS_PER_WAVE = 8


def _sheet(preset: Preset) -> tuple[dict, np.ndarray] | None:
    """The wavy sheet's arguments (defaults filled in) and its waves, if it is analytic."""
    if preset.geometry.kind != "wavy":
        return None
    args = geometry.arguments("wavy", preset.geometry.args)
    waves = check_waves(args["waves"])
    return (args, waves) if 1 <= len(waves) <= MAX_WAVES else None


def thumbnail_divisor(preset: Preset) -> int:
    """By how much a thumbnail may divide this sheet's density arguments (2 or 4)."""
    sheet = _sheet(preset)
    if sheet is None:
        return 2
    args, waves = sheet
    cell = float(args["size"]) / max(int(args["resolution"]) // 4 - 1, 1)
    amplitude, wavelength = np.abs(waves[:, 0]), waves[:, 1]
    gentle = float((amplitude * 2.0 * np.pi / wavelength).sum()) <= GENTLE_SLOPE
    resolved = float(wavelength.min()) >= CELLS_PER_WAVE * cell
    return 4 if gentle and resolved else 2


def defines(preset: Preset) -> dict[str, int | bool]:
    sheet = _sheet(preset)
    return {"WAVES": len(sheet[1])} if sheet else {}


def uniforms(preset: Preset) -> dict[str, object]:
    sheet = _sheet(preset)
    if sheet is None:
        return {}
    amplitude, wavelength, direction, phase = sheet[1].T
    k = 2.0 * np.pi / wavelength
    angle = np.radians(direction)
    rows = np.stack([k * np.cos(angle), k * np.sin(angle), amplitude, phase], axis=1)
    return {"u_waves": [tuple(float(v) for v in row) for row in rows]}
