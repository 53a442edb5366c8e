"""Surfaces are two-sided: an open mesh seen from behind is shaded as its front, mirrored
(TWO_SIDED, compiled where a back face can be seen). Before, the back of a sheet was
black under every light for the films on metals (a review's alligator: all 4,017 object
pixels 0 from behind, coloured with its winding reversed; 6.6 % of a car shell's pixels,
its roof seen through the windows), and grey for the others."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare

pytestmark = pytest.mark.gl


def bowl(flip: bool) -> trimesh.Trimesh:
    """The upper half of a sphere, open at its rim; its winding reversed if ``flip``."""
    sphere = trimesh.creation.uv_sphere(radius=1.0, count=[24, 48])
    upper = sphere.faces[sphere.triangles_center[:, 2] > 0.0]
    faces = upper[:, ::-1] if flip else upper
    return trimesh.Trimesh(sphere.vertices, faces, process=False)


@pytest.mark.parametrize("preset", ["tempered-copper", "cd-rom-ashikhmin", "sphere"])
def test_a_sheets_winding_does_not_change_its_picture(renderer, tmp_path, preset):
    """The bowl and the bowl wound the other way, seen from the same eye (its inside and
    outside in view): the same picture."""
    images = []
    for flip in (False, True):
        path = tmp_path / f"bowl-{flip}.ply"
        bowl(flip).export(path)
        request = RenderRequest(preset=preset, mesh=str(path), width=64, height=64,
                                format="npy", quality="draft", camera_elevation=30.0)
        prepared = prepare(request, local_context(cost_budget=None))
        images.append(renderer.render(prepared.job, preset=prepared.preset).linear)
    covered = images[0][..., 3] == 1.0
    assert covered.sum() > 500
    lit = images[0][covered, :3]
    assert float(np.median(lit.max(axis=-1))) > 0.01  # neither side is black
    np.testing.assert_allclose(images[1][covered, :3], lit, atol=2e-3 * float(lit.max()))
