"""The wavy sheet's per-fragment slope (glsl/lib/waves.glsl) agrees with its float64 twin
(opaline.scene.waves), and lets a thumbnail's mesh be coarse without moving the image."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl import heightfield
from opaline.model import detail
from opaline.model.detail import scene_for_size
from opaline.model.params import RenderRequest
from opaline.model.presets import Generator, get_preset
from opaline.model.request import resolve
from opaline.scene.waves import wave_height


def slope_from_uniforms(rows, x, z):
    """What waves.glsl computes, in float64, from the uniforms it is given."""
    rows = np.asarray(rows)
    arg = rows[:, 0] * x[:, None] + rows[:, 1] * z[:, None] + rows[:, 3]
    factor = rows[:, 2] * np.cos(arg)
    return (factor * rows[:, 0]).sum(-1), (factor * rows[:, 1]).sum(-1)


@pytest.mark.parametrize("name", ["oil-slick", "oil-film"])
def test_uniforms_give_the_heightfield_slope(name):
    preset = get_preset(name)
    waves = preset.geometry.args["waves"]
    rows = heightfield.uniforms(preset)["u_waves"]
    assert heightfield.defines(preset) == {"WAVES": len(waves)}
    x, z = np.random.default_rng(3).uniform(-2.0, 2.0, (2, 500))
    _, hx, hz = wave_height(x, z, waves)
    sx, sz = slope_from_uniforms(rows, x, z)
    np.testing.assert_allclose(sx, hx, atol=1e-12)
    np.testing.assert_allclose(sz, hz, atol=1e-12)


def with_waves(name: str, waves, **geometry):
    preset = get_preset(name)
    args = {**preset.geometry.args, "waves": waves, **geometry}
    return preset.model_copy(update={"geometry": Generator(kind="wavy", **args)})


def test_only_wavy_sheets_of_up_to_eight_waves_are_analytic():
    assert heightfield.defines(get_preset("sphere")) == {}
    many = with_waves("oil-slick", [[0.01, 1.0, 10.0 * k, 0.0] for k in range(9)])
    assert heightfield.defines(many) == {} and heightfield.uniforms(many) == {}
    # ...and then the thumbnail mesh is halved, as every other mesh is.
    assert scene_for_size(many, 256, 256).geometry.args["resolution"] == 96
    assert scene_for_size(get_preset("oil-slick"), 256, 256).geometry.args["resolution"] == 48


def test_only_gentle_resolved_waves_get_the_quarter_mesh():
    """Steep waves need the mesh's heights and outline, short ones its cells: half only."""
    for name in ("oil-slick", "oil-slick-soft", "oil-film"):
        assert detail.thumbnail_divisor(get_preset(name)) == 4, name
    steep = with_waves("oil-slick", [[0.08, 0.3, 20.0, 0.0]])  # slope 1.7
    short = with_waves("oil-slick", [[0.001, 0.3, 20.0, 0.0]])  # 3.5 cells of the quarter
    for preset in (steep, short):
        assert detail.thumbnail_divisor(preset) == 2
        assert scene_for_size(preset, 256, 256).geometry.args["resolution"] == 96


def linear(renderer, preset, **fields):
    job = resolve(RenderRequest(preset=preset.name, width=128, height=128, format="npy",
                                quality="draft", **fields), preset)
    return renderer.render(job, preset).linear


@pytest.mark.gl
@pytest.mark.parametrize("name", ["oil-slick", "oil-film", "oil-slick concentric"])
def test_analytic_slope_on_a_coarse_mesh_matches_vertex_normals_on_a_fine_one(
        renderer, monkeypatch, name):
    """Against the mesh's own (float64) vertex normals on a fine mesh (256 vertices a side
    drawn, 5x finer than the analytic image's 48), the per-fragment slope gives the same
    image, mean error under 0.5 % of the bright end (measured: 0.12 % on oil-slick, 0.02 %
    on oil-film); vertex normals on the same coarse mesh are at least twice as far
    (2.3 % and 0.05 %): the comparison can fail."""
    preset = get_preset(name.split()[0])
    if name.endswith("concentric"):  # the tangent field is the preset's, not dP/dx
        preset = preset.model_copy(update={"tangents": "concentric"})
    analytic = linear(renderer, preset)
    fine = preset.model_copy(update={"geometry": Generator(
        kind="wavy", **{**preset.geometry.args, "resolution": 1024})})
    coarse = preset.model_copy(update={"geometry": Generator(
        kind="wavy", **{**preset.geometry.args, "resolution": 192})})
    for name_ in ("defines", "uniforms"):
        monkeypatch.setattr(heightfield, name_, lambda preset: {})
    monkeypatch.setattr(detail, "thumbnail_divisor", lambda preset: 4)  # same coarsening
    reference, interpolated = linear(renderer, fine), linear(renderer, coarse)
    scale = np.percentile(reference[..., :3], 99)
    error = np.abs(analytic - reference)[..., :3].mean() / scale
    interpolation_error = np.abs(interpolated - reference)[..., :3].mean() / scale
    assert error < 0.005 and error < 0.5 * interpolation_error, (error, interpolation_error)
