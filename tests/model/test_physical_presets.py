"""Thickness fields and the physical presets (issue 14): fields are reproducible, in
range and tile; a field reaches the shader as KHR's thickness texture does; every
physical preset renders at every tier with no non-finite or negative pixel."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.model.tiers import TIERS
from opaline.scene import thickness
from radiance_checks import is_radiance, radiance_problems

PHYSICAL = ["oil-film", "soap-bubble", "cd-rom-grating", "dvd-grating", "nacre-film",
            "anodised-titanium", "tempered-steel", "tempered-copper"]


@pytest.mark.parametrize("kind", ["swirl", "drain", "platelets"])
def test_fields_are_reproducible_and_in_range(kind):
    a = thickness.build(kind, resolution=64, seed=5)
    assert a.shape == (64, 64) and a.dtype == np.float32
    assert np.array_equal(a, thickness.build(kind, resolution=64, seed=5))
    assert not np.array_equal(a, thickness.build(kind, resolution=64, seed=6))
    assert a.min() >= 0.0 and a.max() <= 1.0 and a.max() - a.min() > 0.3


def test_swirl_tiles():
    """Opposite edges meet as neighbouring rows do: no seam on a repeating texture."""
    a = thickness.build("swirl", resolution=128, seed=2)
    inner = np.abs(np.diff(a, axis=0)).mean()
    assert np.abs(a[0] - a[-1]).mean() < 3.0 * inner
    assert np.abs(a[:, 0] - a[:, -1]).mean() < 3.0 * np.abs(np.diff(a, axis=1)).mean()


def test_drain_is_thinnest_at_the_top():
    a = thickness.build("drain", resolution=64, seed=1)
    assert a[:8].mean() < 0.1 < 0.8 < a[-8:].mean()


def test_platelets_are_flat_cells():
    a = thickness.build("platelets", resolution=64, seed=1, cells=20)
    assert len(np.unique(a)) <= 20


def test_file_field_and_bad_arguments(tmp_path):
    path = tmp_path / "t.png"
    Image.fromarray(np.full((4, 6), 51, dtype=np.uint8)).save(path)
    assert np.allclose(thickness.build("file", path=str(path)), 0.2)
    with pytest.raises(ValueError, match="seed"):
        thickness.build("swirl", seed=-1)
    with pytest.raises(ValueError, match="unknown"):
        thickness.build("marble")


def render(renderer, preset, size=48, **fields):
    preset = get_preset(preset) if isinstance(preset, str) else preset
    request = RenderRequest(preset=preset.name, width=size, height=size, format="npy", **fields)
    return renderer.render(resolve(request, preset), preset=preset).linear


@pytest.mark.gl
@pytest.mark.parametrize("quality", list(TIERS))
@pytest.mark.parametrize("name", PHYSICAL)
def test_physical_presets_render_finite_and_non_negative_at_every_tier(renderer, name, quality):
    image = render(renderer, name, quality=quality)
    assert is_radiance(image), radiance_problems(image)
    # Something is lit: the colour source is not silently off.
    assert image[..., :3].max() > 0.01


@pytest.mark.gl
def test_thickness_field_maps_to_min_max(renderer):
    """min = max = d on a preset with a field renders exactly as the field-less film of
    thickness d; a real range changes the picture."""
    preset = get_preset("oil-film")
    bare = preset.model_copy(update={"thickness_map": None, "name": "oil-film"})
    flat = render(renderer, preset, film_thickness_min=300.0, film_thickness_max=300.0)
    assert np.allclose(flat, render(renderer, bare, film_thickness_max=300.0), atol=1e-6)
    varied = render(renderer, preset)
    assert np.abs(varied - flat).max() > 0.01


@pytest.mark.gl
def test_transparent_film_shows_the_background_exactly(renderer):
    """A soap film of thickness 0 reflects nothing and transmits everything: with no
    specular, the bubble's pixels display as the background colour itself (the preset's
    colour, not its environment behind it)."""
    preset = get_preset("soap-bubble")
    request = RenderRequest(preset="soap-bubble", width=32, height=32, quality="draft",
                            film_thickness_min=0.0, film_thickness_max=0.0, ks=0.0,
                            environment_background=False,
                            format="png16")  # float display values
    display = renderer.render(resolve(request, preset), preset=preset).display
    assert np.abs(display[..., :3] - np.array(preset.background)).max() < 2e-3
    # And a real film tints it: not the background everywhere.
    request = RenderRequest(preset="soap-bubble", width=32, height=32, quality="draft", ks=0.0,
                            environment_background=False, format="png16")
    tinted = renderer.render(resolve(request, preset), preset=preset).display
    assert np.abs(tinted[..., :3] - np.array(preset.background)).max() > 0.02
