"""Thumbnails draw a coarser mesh (opaline.model.detail), and it does not change how they look."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model import detail
from opaline.model.params import RenderRequest
from opaline.model.presets import all_presets, build_assets, get_preset
from opaline.model.request import resolve


def triangles(preset) -> int:
    return build_assets(preset)[0].triangle_count


@pytest.mark.parametrize("name", ["sphere", "oil-slick", "cd-rom"])
def test_thumbnails_get_about_a_quarter_of_the_triangles(name):
    preset = get_preset(name)
    full, thumb = triangles(preset), triangles(detail.scene_for_size(preset, 256, 256))
    assert thumb <= 0.55 * full, (thumb, full)  # the annulus halves only its segments
    assert detail.scene_for_size(preset, 512, 256) is preset
    assert detail.scene_for_size(preset, 256, 256).scene_key() != preset.scene_key()


def test_every_preset_keeps_a_valid_mesh_when_coarse():
    for preset in all_presets().values():
        mesh = build_assets(detail.scene_for_size(preset, 64, 64))[0]
        assert mesh.triangle_count > 0


@pytest.mark.gl
@pytest.mark.parametrize("name", ["sphere", "oil-slick"])
def test_coarse_mesh_image_is_within_a_level_on_average(renderer, monkeypatch, name):
    """The 256² image from the coarse mesh differs from the full mesh's by under one 8-bit
    level on average (the sphere's rings are the most sensitive to normal interpolation)."""
    job = resolve(RenderRequest(preset=name, quality="standard"), get_preset(name))
    coarse = renderer.render(job).pixels.astype(int)
    monkeypatch.setattr("opaline.gl.renderer.scene_for_size", lambda p, w, h: p)
    full = renderer.render(job).pixels.astype(int)
    difference = np.abs(coarse - full)
    assert 0 < difference.mean() < 1.0, difference.mean()
