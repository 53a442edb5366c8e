"""A preset's fields on its own sphere do not tile in v: v runs pole to pole. Tiled, a
pole's coarse mip level (u squeezed to a point there) mixed in the other pole's rows, and
the graded oxides (thin at the top, thick at the bottom) showed a dot of the far pole's
colour at each pole (a review saw it on anodised-titanium and tempered-steel)."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare

pytestmark = pytest.mark.gl
SIZE = 96


def pole_contrast(renderer, preset: str, elevation: float) -> float:
    """The largest difference between the pole's pixels and the median of a ring about
    them, over that median's brightest channel (the preset's tilt taken off, so the pole
    is the image's centre; a smooth map, so the film alone makes the colour)."""
    request = RenderRequest(preset=preset, width=SIZE, height=SIZE, format="npy",
                            quality="draft", environment="neutral", camera_elevation=elevation)
    prepared = prepare(request, local_context(cost_budget=None))
    upright = prepared.preset.model_copy(update={"rotation_deg": (0.0, 0.0, 0.0)})
    image = renderer.render(prepared.job, preset=upright).linear[..., :3]
    centre = SIZE // 2
    pole = image[centre - 4:centre + 4, centre - 4:centre + 4].reshape(-1, 3)
    rows, columns = np.mgrid[:SIZE, :SIZE]
    radius = np.hypot(rows - centre + 0.5, columns - centre + 0.5)
    ring = np.median(image[(radius > 6) & (radius < 10)], axis=0)
    return float(np.abs(pole - ring).max() / max(float(ring.max()), 1e-6))


@pytest.mark.parametrize("preset", ["anodised-titanium", "tempered-steel"])
@pytest.mark.parametrize("elevation", [89.0, -89.0])
def test_a_graded_field_has_no_dot_at_the_poles(renderer, preset, elevation):
    # Tiled in v: 1.14 and 0.79 (titanium's top and bottom), 0.66 and 0.54 (steel's); now
    # 0.33, 0.18, 0.15, 0.13: what is left is the grade itself, from pole to ring.
    assert pole_contrast(renderer, preset, elevation) < 0.45
