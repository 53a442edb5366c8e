"""The rim of a glossy ball under an environment reflects the horizon, pixel by pixel. A
vertex normal interpolated across a silhouette's triangle can face away from the view
though the triangle faces it; every sample of the lobe then reflected under the surface,
and soap-bubble showed black pixels on the rim among bright neighbours (a review found them
at the same pixels under every map; a coat's reflection had them too)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import median_filter

from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare

pytestmark = pytest.mark.gl


def test_no_black_pixels_on_the_rim(renderer):
    request = RenderRequest(preset="soap-bubble", width=256, height=256, format="npy",
                            quality="standard", environment="sky")
    prepared = prepare(request, local_context(cost_budget=None))
    image = renderer.render(prepared.job, preset=prepared.preset).linear
    luminance = image[..., :3].mean(axis=-1)
    around = median_filter(luminance, size=3)
    covered = median_filter(image[..., 3], size=3) == 1.0
    dark = covered & (around > 0.02) & (luminance < 0.25 * around)
    assert not dark.any(), np.argwhere(dark)[:8].tolist()  # before: 6 on the bubble
