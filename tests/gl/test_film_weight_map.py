"""A .glb's factor texture (KHR iridescenceTexture, R) weighs its film texel by texel,
times film_weight: where the texture is 0 the surface is the bare substrate, drawn as a
render of weight 0 draws it; where it is 1 the whole film, as a render of weight 1; a
constant texture of 0 draws the bare substrate everywhere. (Before, the texture was
carried to the export but the film was drawn whole.)"""

from __future__ import annotations

import io

import numpy as np
import pygltflib
import pytest
from PIL import Image

from mesh_helpers import glb_with_film
from opaline.local.context import local_context
from opaline.local.export import export_material
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare

pytestmark = pytest.mark.gl

FILM = {"iridescence": "thin-film", "film_ior": 1.4, "film_thickness_min": 500.0,
        "film_thickness_max": 500.0, "substrate_ior": 2.4, "mdf": "ashikhmin", "ex": 20.0,
        "ey": 20.0, "kd": 0.0, "ks": 1.0, "theta1": 0.0, "theta2": 0.0, "environment": "none"}


def with_factor(factor: np.ndarray) -> bytes:
    """The sphere as a .glb whose film has ``factor`` (uint8) as its iridescenceTexture."""
    document = pygltflib.GLTF2.load_from_bytes(export_material({"preset": "sphere"}, "glb"))
    out = io.BytesIO()
    Image.fromarray(np.stack([factor, 255 - factor, factor], axis=-1), "RGB").save(out, "PNG")
    return glb_with_film(document, {"iridescenceTexture": out.getvalue()},
                         {"iridescenceFactor": 1.0})


def draw(renderer, path, **fields) -> np.ndarray:
    request = RenderRequest(preset="sphere", mesh=str(path), width=96, height=96,
                            format="npy", quality="draft", **{**FILM, **fields})
    prepared = prepare(request, local_context(cost_budget=None))
    return renderer.render(prepared.job, preset=prepared.preset).linear


def test_the_factor_texture_weighs_the_film_texel_by_texel(renderer, tmp_path):
    stripes = np.zeros((32, 64), dtype=np.uint8)
    for start in range(0, 64, 16):  # along u, the whole film and none in turn
        stripes[:, start + 8:start + 16] = 255
    textured, plain = tmp_path / "stripes.glb", tmp_path / "plain.glb"
    textured.write_bytes(with_factor(stripes))
    plain.write_bytes(export_material({"preset": "sphere"}, "glb"))
    prepared = prepare(RenderRequest(preset="sphere", mesh=str(textured), **FILM),
                       local_context(cost_budget=None))
    assert prepared.preset.weight_map is not None
    found = draw(renderer, textured)
    film = draw(renderer, plain, film_weight=1.0)
    bare = draw(renderer, plain, film_weight=0.0)
    lit = (found[..., 3] == 1.0) & (np.maximum(film, bare)[..., :3].max(axis=-1) > 1e-3)
    scale = float(np.maximum(film, bare)[..., :3].max())
    near_film = np.abs(found - film)[..., :3].max(axis=-1) <= 2e-3 * scale
    near_bare = np.abs(found - bare)[..., :3].max(axis=-1) <= 2e-3 * scale
    differ = lit & (np.abs(film - bare)[..., :3].max(axis=-1) > 2e-2 * scale)
    assert differ.sum() > 200  # the film shows: the two sides can be told apart
    film_side, bare_side = (differ & near_film).sum(), (differ & near_bare).sum()
    print(f"{differ.sum()} lit pixels: {film_side} drawn as the film, {bare_side} bare")
    assert film_side > 0.2 * differ.sum() and bare_side > 0.2 * differ.sum()
    # Besides the stripes' filtered edges, each pixel is one or the other.
    assert (differ & ~near_film & ~near_bare).sum() < 0.3 * differ.sum()


def test_a_factor_texture_of_zero_draws_the_bare_substrate(renderer, tmp_path):
    zero, plain = tmp_path / "zero.glb", tmp_path / "plain.glb"
    zero.write_bytes(with_factor(np.zeros((8, 8), dtype=np.uint8)))
    plain.write_bytes(export_material({"preset": "sphere"}, "glb"))
    found = draw(renderer, zero)
    bare = draw(renderer, plain, film_weight=0.0)
    film = draw(renderer, plain, film_weight=1.0)
    assert np.abs(film - bare).max() > 0.05 * float(film[..., :3].max())
    np.testing.assert_allclose(found, bare, atol=1e-5 * float(bare[..., :3].max()))
