"""The built-in product-shot maps (opaline.scene.studio): the studio's room, panels and
hard light, the neutral gradient, and the bright split that turns a small source into
one light (opaline.scene.bright)."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.params import RenderRequest
from opaline.scene import environments, studio
from opaline.scene.mediancut import LUMA, directions


@pytest.mark.parametrize("name", ["studio", "neutral"])
def test_product_maps_are_finite_and_non_negative(name):
    radiance = environments.resolve_map(name, None)
    assert radiance.dtype == np.float32 and radiance.ndim == 3 and radiance.shape[2] == 3
    assert np.all(np.isfinite(radiance)) and radiance.min() > 0.0  # no black anywhere
    assert environments.resolve_map(name, None) is radiance  # built once, kept
    assert not radiance.flags.writeable


def test_studio_is_a_room_with_panels_and_the_key_above_front():
    """The brightest region is the key, above the object on the camera's side (+z); the
    other panels are sharp rectangles well above the walls, which are a gradient, not flat."""
    radiance = environments.resolve_map("studio", None).astype(np.float64) / studio.LEVEL
    d, _ = directions(*radiance.shape[:2])
    radiance[spot_cone(d, 1.5)] = 0.0  # the hard light: test_studio_has_one_hard_light
    luma = radiance @ LUMA
    brightest = d[luma >= 0.98 * luma.max()]
    assert len(brightest) > 500  # a large panel, not a spot
    assert np.all(brightest[:, 1] > 0.5) and np.all(brightest[:, 2] > 0.0)
    assert brightest[:, 2].mean() > 0.3  # in front, toward the camera
    panels, walls = luma >= 0.3, luma[luma <= 0.18]  # the dimmest panel is 0.33
    assert walls.max() > 2.5 * walls.min()  # a gradient
    assert 0.02 < float(np.mean(walls)) < 0.1
    # Panels have sharp edges: few texels lie between wall and panel levels (the
    # 2×2-averaged edge texels only).
    between = ~panels & (luma > 0.18)
    assert between.sum() < 0.25 * panels.sum()
    # Six panels: count the separate bright regions along the horizon and overhead.
    scipy_ndimage = pytest.importorskip("scipy.ndimage")
    _, count = scipy_ndimage.label(np.concatenate([panels, panels[:, :1]], 1))
    assert count >= 6


def spot_cone(d: np.ndarray, widen: float) -> np.ndarray:
    axis = np.asarray(studio.SPOT_DIRECTION) / np.linalg.norm(studio.SPOT_DIRECTION)
    return (d @ axis) >= np.cos(np.radians(widen * studio.SPOT_RADIUS_DEG))


def test_studio_has_one_hard_light():
    """A small round source, far above the panels, which split_bright turns into one
    light carrying its irradiance (what the map keeps of it plus the light: the total)."""
    from opaline.scene.bright import split_bright

    radiance = environments.resolve_map("studio", None).astype(np.float64)
    d, solid = directions(*radiance.shape[:2])
    luma = radiance @ LUMA
    hot = luma > 100.0 * studio.LEVEL
    assert hot.any() and np.all(spot_cone(d, 1.5)[hot])
    kept, lights, irradiance = split_bright(radiance.astype(np.float32))
    assert len(lights) == 1
    axis = np.asarray(studio.SPOT_DIRECTION) / np.linalg.norm(studio.SPOT_DIRECTION)
    assert lights[0] @ axis > np.cos(np.radians(studio.SPOT_RADIUS_DEG))
    cone = spot_cone(d, 1.5)
    total = (radiance[cone] * solid[np.nonzero(cone)[0]]).sum(0)
    carried = irradiance[0] + (kept[cone] * solid[np.nonzero(cone)[0]]).sum(0)
    np.testing.assert_allclose(carried, total, rtol=1e-4)
    np.testing.assert_allclose(total, studio.SPOT_IRRADIANCE, rtol=0.15)  # the disc, in texels


def test_studio_is_the_old_studios_light_at_its_level():
    """The room's balance is the earlier studio's: the total and the irradiance on the faces
    toward the camera and upward, over ``LEVEL``, in its range (1.70, 0.70, 0.86)."""
    radiance = environments.resolve_map("studio", None).astype(np.float64) / studio.LEVEL
    d, solid = directions(*radiance.shape[:2])
    radiance[spot_cone(d, 1.5)] = 0.0  # the hard light came after
    energy = (radiance @ LUMA) * solid
    assert 1.4 < energy.sum() < 2.1
    assert 0.45 < (energy * np.clip(d[..., 2], 0, None)).sum() < 0.85  # toward +z
    assert 0.7 < (energy * np.clip(d[..., 1], 0, None)).sum() < 1.05  # upward


def test_neutral_is_a_featureless_gradient():
    radiance = environments.resolve_map("neutral", None)
    assert radiance.max() <= 0.45
    np.testing.assert_array_equal(radiance, radiance[:, :1].repeat(radiance.shape[1], 1))
    rows = radiance[:, 0] @ LUMA  # row 0 is the zenith
    assert np.all(np.diff(rows) < 0) and rows[0] > 5 * rows[-1]


def test_neutral_is_listed_where_the_built_ins_are():
    assert "neutral" in environments.BUILTIN
    with pytest.raises(ValueError, match="studio, neutral, sky"):
        environments.check_name("gallery", None)
    description = RenderRequest.model_fields["environment"].description or ""
    assert all(f"'{name}'" in description for name in environments.BUILTIN)


def test_a_small_source_becomes_one_light_and_distant_ones_stay_apart():
    """merge_close folds median cut's fragments of one source (a fraction of a degree
    apart) into one light at their energy's centroid, keeping the irradiance; lights
    further apart than MERGE_DEGREES stay separate."""
    from opaline.scene.bright import MERGE_DEGREES, merge_close, split_bright

    sun = split_bright(environments.sky())
    assert len(sun[1]) == 1  # median cut alone gives 3 within 0.5° of each other
    def unit(v):
        return np.asarray(v, dtype=np.float64) / np.linalg.norm(v)

    near = np.radians(0.4 * MERGE_DEGREES)
    far = np.radians(2.0 * MERGE_DEGREES)
    direction = np.array([unit([0, 0, 1]), unit([np.sin(near), 0, np.cos(near)]),
                          unit([0, np.sin(far), np.cos(far)])])
    irradiance = np.array([[3.0, 3.0, 3.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    merged_d, merged_e = merge_close(direction, irradiance)
    assert len(merged_d) == 2
    np.testing.assert_allclose(merged_e.sum(0), irradiance.sum(0))
    np.testing.assert_allclose(merged_e[0], [4.0, 4.0, 4.0])  # the brightest keeps its near one
    centroid = unit(3.0 * direction[0] + 1.0 * direction[1])
    np.testing.assert_allclose(merged_d[0], centroid, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(merged_d, axis=1), 1.0)
