"""The wavy sheet's slope evaluated per fragment (glsl/lib/waves.glsl): its define and
its uniforms (the mesh density that is then enough: model/detail.py).

With vertex normals, a thumbnail of an oil slick needed the mesh fine: its bands follow
the normal closely, and at half the preset's density they had already moved (FLIP 0.018
against the full mesh at 256²). With the slope computed where it is shaded, the mesh
only carries positions, which a gentle swell barely lifts off a plane: a thumbnail may
then draw a quarter of the density. Steep or short waves (a user's preset may have any)
still need the mesh for their heights, occlusion and outline, and keep the half.
"""

from __future__ import annotations

import numpy as np

from opaline.gl.uniforms import Uniforms
from opaline.model.detail import analytic_sheet
from opaline.model.presets import Preset


def defines(preset: Preset) -> dict[str, int | bool]:
    sheet = analytic_sheet(preset)
    return {"WAVES": len(sheet[1])} if sheet else {}


def uniforms(preset: Preset) -> Uniforms:
    sheet = analytic_sheet(preset)
    if sheet is None:
        return {}
    amplitude, wavelength, direction, phase = sheet[1].T
    k = 2.0 * np.pi / wavelength
    angle = np.radians(direction)
    rows = np.stack([k * np.cos(angle), k * np.sin(angle), amplitude, phase], axis=1)
    return {"u_waves": [tuple(float(v) for v in row) for row in rows]}
