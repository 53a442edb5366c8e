"""The wavy sheet's slope evaluated per fragment (glsl/lib/waves.glsl): its define, its
uniforms, and the mesh density that is then enough.

With vertex normals, a thumbnail of an oil slick needed the mesh fine: its bands follow
the normal closely, and at half the preset's density they had already moved (FLIP 0.018
against the full mesh at 256²). With the slope computed where it is shaded, the mesh
only carries positions, which a swell of amplitude 0.02 barely lifts off a plane.
"""

from __future__ import annotations

import numpy as np

from opaline.model.presets import Preset
from opaline.scene.waves import DEFAULT_WAVES, check_waves

MAX_WAVES = 8  # more (a preset may list any number) keep the mesh's normals
# How much coarser a thumbnail's sheet may be than the preset's when its slope is
# analytic (gl/detail.py halves every other mesh): a quarter of the density, a
# sixteenth of the triangles.
THUMBNAIL_DIVISOR = 4


def _waves(preset: Preset) -> np.ndarray | None:
    if preset.geometry.kind != "wavy":
        return None
    waves = check_waves(preset.geometry.args.get("waves", DEFAULT_WAVES))
    return waves if 1 <= len(waves) <= MAX_WAVES else None


def analytic(preset: Preset) -> bool:
    """Whether this preset's surface is shaded with the heightfield's own slope."""
    return _waves(preset) is not None


def defines(preset: Preset) -> dict[str, int | bool]:
    waves = _waves(preset)
    return {"WAVES": len(waves)} if waves is not None else {}


def uniforms(preset: Preset) -> dict[str, object]:
    waves = _waves(preset)
    if waves is None:
        return {}
    amplitude, wavelength, direction, phase = waves.T
    k = 2.0 * np.pi / wavelength
    angle = np.radians(direction)
    rows = np.stack([k * np.cos(angle), k * np.sin(angle), amplitude, phase], axis=1)
    return {"u_waves": [tuple(float(v) for v in row) for row in rows]}
