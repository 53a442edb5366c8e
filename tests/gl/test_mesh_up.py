"""mesh_up=z: a Z-up file (many scans and CAD exports; OBJ, PLY and STL cannot say) is
turned so that its +z is up, before its normals, tangents, maps and framing. Before, such
a file lay on its side (a review's Nefertiti bust was seen from its base), and a preset's
top-to-bottom grade ran across it."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare

pytestmark = pytest.mark.gl


def draw(renderer, path, **fields) -> np.ndarray:
    request = RenderRequest(preset="anodised-titanium", mesh=str(path), width=64, height=64,
                            format="npy", quality="draft", environment="neutral", **fields)
    prepared = prepare(request, local_context(cost_budget=None))
    return renderer.render(prepared.job, preset=prepared.preset).linear


def test_a_z_up_file_draws_as_its_y_up_copy(renderer, tmp_path):
    tall = trimesh.creation.cone(radius=0.4, height=2.0, sections=48)  # its tip along +z
    tall.export(tmp_path / "z-up.ply")
    turned = tall.copy()
    turned.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0]))
    turned.export(tmp_path / "y-up.ply")
    lying = draw(renderer, tmp_path / "z-up.ply")
    upright = draw(renderer, tmp_path / "y-up.ply")
    standing = draw(renderer, tmp_path / "z-up.ply", mesh_up="z")
    covered = upright[..., 3] == 1.0
    assert covered.sum() > 300
    assert np.array_equal(standing[..., 3], upright[..., 3])
    np.testing.assert_allclose(standing[covered, :3], upright[covered, :3], atol=1e-4)
    assert not np.array_equal(lying[..., 3], upright[..., 3])  # the default: +y is up


def test_the_default_keeps_a_meshs_key(tmp_path):
    trimesh.creation.box().export(tmp_path / "box.ply")
    context = local_context(cost_budget=None)
    plain = prepare(RenderRequest(preset="sphere", mesh=str(tmp_path / "box.ply")), context)
    named = prepare(RenderRequest(preset="sphere", mesh=str(tmp_path / "box.ply"),
                                  mesh_up="y"), context)
    turned = prepare(RenderRequest(preset="sphere", mesh=str(tmp_path / "box.ply"),
                                   mesh_up="z"), context)
    assert "up" not in plain.preset.geometry.args
    assert plain.preset.scene_key() == named.preset.scene_key() != turned.preset.scene_key()
