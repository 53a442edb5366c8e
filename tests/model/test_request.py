"""Request resolution (opaline.model.request): merge order, tiers, cost, cache keys."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from opaline.model.params import MATERIAL_FIELDS, RenderFields, RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import CostError, Job, check_cost, resolve
from opaline.model.tiers import TIERS

ROOT = Path(__file__).resolve().parents[2]


def custom_preset(**defaults):
    """The sphere scene with the given [defaults] and no others."""
    update = {"name": "custom", "defaults": RenderFields(**defaults)}
    return get_preset("sphere").model_copy(update=update)


def test_builtin_defaults_fill_everything():
    """With empty preset defaults and an empty request, docs/design.md §5's defaults apply."""
    job = resolve(RenderRequest(), custom_preset())
    m = job.material
    assert (m.mdf, m.ex, m.ey, m.mu_f, m.alpha, m.beta) == ("multipeak", 100.0, 10.0, 8.5, 2.0, 1.2)
    assert (m.theta1, m.theta2, m.f0) == (0.1, 0.2, 1.0)
    assert (job.width, job.height, job.format) == (256, 256, "png")
    assert job.quality == "standard" and job.transparent is False
    for field in dataclasses.fields(Job):
        # None means "the preset's" (light, camera) or "no environment".
        if field.name not in ("light_azimuth", "light_elevation", "auto") and not field.name.startswith(
                ("camera_", "environment")):
            assert getattr(job, field.name) is not None, field.name


def test_preset_overrides_builtin():
    """A preset's [defaults] beat the built-in defaults."""
    preset = custom_preset(width=64, mu_f=3.0, albedo=(0.1, 0.2, 0.3), tonemap="reinhard")
    job = resolve(RenderRequest(), preset)
    assert job.width == 64 and job.height == 256
    assert job.material.mu_f == 3.0 and job.material.alpha == 2.0
    assert job.material.albedo == (0.1, 0.2, 0.3)
    assert job.tonemap == "reinhard"


def test_request_overrides_preset():
    """A request's fields beat the preset's defaults; unset fields keep the preset's."""
    preset = custom_preset(width=64, mu_f=3.0, albedo=(0.1, 0.2, 0.3), tonemap="reinhard")
    job = resolve(RenderRequest(width=32, mu_f=5.0, albedo=(0.9, 0.8, 0.7)), preset)
    assert job.width == 32 and job.material.mu_f == 5.0
    assert job.material.albedo == (0.9, 0.8, 0.7)
    assert job.tonemap == "reinhard"


def test_named_preset_is_looked_up():
    """Without an explicit preset object, the request's preset name is used (sphere by default)."""
    assert resolve(RenderRequest(preset="oil-slick")).material.alpha == 20.0
    assert resolve(RenderRequest(preset="oil-slick")).preset == "oil-slick"
    assert resolve(RenderFields()).preset == "sphere"


@pytest.mark.parametrize("tier", sorted(TIERS))
def test_tier_fills_samples_wavelengths_aa(tier):
    """An unset samples/wavelengths/aa comes from the request's quality tier."""
    job = resolve(RenderRequest(quality=tier), custom_preset())
    assert job.quality == tier
    assert (job.samples, job.wavelengths, job.aa) == (
        TIERS[tier].samples, TIERS[tier].wavelengths, TIERS[tier].aa)


@pytest.mark.parametrize("tier", sorted(TIERS))
def test_a_film_takes_its_own_wavelengths_from_the_tier(tier):
    """Per colour source (bench/white_point.py): a film on a dielectric takes the tier's
    film_wavelengths (the fast path at draft and standard), on a metal its
    metal_film_wavelengths; the rotation keeps wavelengths; a request's own value wins."""
    want = TIERS[tier]
    film = resolve(RenderRequest(preset="oil-film", quality=tier))
    metal = resolve(RenderRequest(preset="tempered-steel", quality=tier))
    stack = resolve(RenderRequest(preset="bragg-mirror", quality=tier))
    assert stack.wavelengths == want.stack_wavelengths
    rotation = resolve(RenderRequest(preset="sphere", quality=tier))
    assert film.wavelengths == want.film_wavelengths
    assert metal.wavelengths == want.metal_film_wavelengths
    assert rotation.wavelengths == want.wavelengths
    assert resolve(RenderRequest(preset="oil-film", quality=tier, wavelengths=24)).wavelengths == 24
    assert resolve(RenderRequest(preset="sphere", quality=tier, iridescence="thin-film")
                   ).wavelengths == want.film_wavelengths
    assert TIERS["draft"].film_wavelengths == 0 and TIERS["standard"].film_wavelengths == 0
    assert TIERS["standard"].metal_film_wavelengths == 16
    # Over 8 samples 16 wavelengths a sample leave colour noise on films and stacks (the
    # accuracy grid): high takes 32 on a dielectric; a metal keeps 16 (its cost, tiers.py).
    assert TIERS["high"].film_wavelengths == 32 and TIERS["high"].metal_film_wavelengths == 16
    # A stack's 16-bin fast path at standard left morpho at FLIP 0.061: 32 wavelengths.
    assert TIERS["standard"].stack_wavelengths == 32


def test_tiers_are_ordered():
    """Tiers are the four of docs/design.md §8, samples growing toward a spectral reference."""
    assert list(TIERS) == ["draft", "standard", "high", "reference"]
    samples = [TIERS[t].samples for t in TIERS]
    assert samples == sorted(samples) and samples[0] < samples[-1]
    assert TIERS["reference"].wavelengths >= 3


def test_explicit_fields_override_the_tier():
    """samples, wavelengths and aa given in the request win over the tier's."""
    job = resolve(RenderRequest(quality="reference", samples=2, wavelengths=0, aa="analytic"),
                  custom_preset())
    assert (job.samples, job.wavelengths, job.aa) == (2, 0, "analytic")
    job = resolve(RenderRequest(quality="draft", samples=9, wavelengths=5, aa="none"),
                  custom_preset())
    assert (job.samples, job.wavelengths, job.aa) == (9, 5, "none")


def test_cost_formula():
    """Cost is width × height × samples × max(wavelengths, 3)."""
    size = {"width": 20, "height": 30, "samples": 7}
    rgb = resolve(RenderRequest(**size, wavelengths=0), custom_preset())
    spectral = resolve(RenderRequest(**size, wavelengths=16), custom_preset())
    assert rgb.cost == 20 * 30 * 7 * 3
    assert spectral.cost == 20 * 30 * 7 * 16


def test_check_cost_refuses_over_budget_with_the_budget():
    """check_cost accepts a cost equal to the budget and refuses one over, naming the budget."""
    job = resolve(RenderRequest(width=64, height=48, samples=5, wavelengths=8), custom_preset())
    check_cost(job, job.cost)
    budget = job.cost - 1
    with pytest.raises(CostError) as info:
        check_cost(job, budget)
    assert str(budget) in str(info.value)
    assert isinstance(info.value, ValueError)


def key(preset_name="sphere", **fields):
    preset = get_preset(preset_name)
    job = resolve(RenderRequest(preset=preset_name, **fields), preset)
    return job.cache_key(preset.scene_key())


def test_cache_key_stable_for_equal_requests():
    """Two equal requests, built separately, have the same cache key."""
    a = key(mu_f=3.0, width=64, albedo=(0.1, 0.2, 0.3))
    b = key(albedo=(0.1, 0.2, 0.3), width=64, mu_f=3.0)
    assert a == b
    assert key() == key()
    # Setting a field to the value it would have anyway is the same render.
    assert key(width=256) == key()


def test_cache_key_stable_across_processes():
    """The key does not depend on the process (no id()- or hash()-seeded parts)."""
    code = ("from opaline.model.params import RenderRequest; from opaline.model.presets import get_preset; "
            "from opaline.model.request import resolve; p = get_preset('cd-rom'); "
            "print(resolve(RenderRequest(preset='cd-rom', mu_f=3.0), p).cache_key(p.scene_key()))")
    # The checkout's package (service/): an installed opaline hashes other shader sources.
    env = {**os.environ, "PYTHONPATH": str(ROOT / "service"), "PYTHONHASHSEED": "12345"}
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True,
                         text=True, check=True, timeout=60)
    assert out.stdout.strip() == key("cd-rom", mu_f=3.0)


CHANGED_MATERIAL = {
    "mdf": "ashikhmin", "ex": 101.0, "ey": 11.0, "mu_f": 8.6, "alpha": 2.1, "beta": 1.3,
    "theta1": 0.11, "theta2": 0.21, "kd": 0.3, "ks": 0.6, "albedo": (0.7, 0.7, 0.73), "f0": 0.9,
    "iridescence": "thin-film", "film_ior": 1.4, "film_thickness_min": 120.0,
    "film_thickness_max": 420.0, "substrate_ior": 1.33, "grating_pitch": 0.74,
    "grating_orders": 2, "grating_depth": 120.0, "substrate": "conductor", "metal": "artist",
    "metal_f0": (0.9, 0.6, 0.3), "metal_edge_tint": (1.0, 0.9, 0.8), "film_weight": 0.5,
    "film_stack_pairs": 3, "film_spacer_ior": 1.2, "film_spacer_thickness": 90.0,
    "coat_weight": 0.5, "coat_roughness": 0.2, "coat_ior": 1.6,
}


def test_changed_material_table_covers_every_field():
    """The table below changes every material field there is."""
    assert set(CHANGED_MATERIAL) == set(MATERIAL_FIELDS)


@pytest.mark.parametrize(("field", "value"), sorted(CHANGED_MATERIAL.items()))
def test_cache_key_changes_with_material(field, value):
    """Changing any material field changes the cache key."""
    assert key(**{field: value}) != key()


@pytest.mark.parametrize(
    ("field", "value"),
    [("width", 128), ("height", 128), ("format", "png16"), ("format", "npy"), ("quality", "draft"),
     ("quality", "high"), ("samples", 3), ("wavelengths", 32), ("aa", "none"), ("exposure", 2.0),
     ("tonemap", "none"), ("transparent", True), ("light_azimuth", 30.0),
     ("light_elevation", 10.0), ("environment_blur", 0.5)],
)
def test_cache_key_changes_with_render_fields(field, value):
    """Changing size, format, tier or any other render field changes the cache key."""
    assert key(**{field: value}) != key()


def test_cache_key_changes_with_preset():
    """The same material on another preset (or another scene) is another key."""
    material = resolve(RenderRequest(preset="cd-rom")).material.model_dump()
    assert key("cd-rom") != key("cd-rom-wide", **material)
    job = resolve(RenderRequest(preset="cd-rom"))
    assert job.cache_key("scene-a") != job.cache_key("scene-b")


def test_canonical_form_is_json():
    """The canonical form serialises to JSON with every Job field, the tier as its name (a
    tier job has no auto pick, and leaves it out so its key stays what it was before
    quality=auto)."""
    fields = {f.name for f in dataclasses.fields(Job)} - {"tier"} | {"quality"}
    job = resolve(RenderRequest(preset="nacre"))
    data = json.loads(json.dumps(job.canonical()))
    assert set(data) == fields and data["quality"] == "standard"
    picked = resolve(RenderRequest(preset="nacre", quality="auto"))
    assert set(json.loads(json.dumps(picked.canonical()))) == fields | {"auto"}
    assert data["material"]["mu_f"] == job.material.mu_f
