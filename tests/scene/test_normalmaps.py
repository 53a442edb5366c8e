"""Procedural normal maps: unit, seeded, tileable, green-up, and the shapes they promise."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from opaline.scene import normalmaps

GENERATORS = {"bumps": normalmaps.bumps, "nacre": normalmaps.nacre}


@pytest.fixture(params=list(GENERATORS), ids=list(GENERATORS))
def generator(request):
    return GENERATORS[request.param]


def _slopes(n: np.ndarray):
    """dh/du and dh/dv from tangent-space normals n ∝ (-dh/du, -dh/dv, 1)."""
    n = n.astype(np.float64)
    return -n[..., 0] / n[..., 2], -n[..., 1] / n[..., 2]


def _wrapped(delta, period):
    return (delta + period / 2) % period - period / 2


def test_maps_are_unit_normals_facing_out(generator):
    """Maps are (H, W, 3) float32, finite, unit length, with z > 0 (toward the viewer)."""
    n = generator(resolution=96, seed=3)
    assert n.shape == (96, 96, 3) and n.dtype == np.float32 and n.flags.c_contiguous
    assert np.isfinite(n).all()
    np.testing.assert_allclose(np.linalg.norm(n.astype(np.float64), axis=-1), 1.0, atol=1e-6)
    assert n[..., 2].min() > 0.0


def test_maps_are_deterministic(generator):
    """The same seed gives the same bytes; another seed gives a different map."""
    a = generator(resolution=64, seed=7)
    b = generator(resolution=64, seed=7)
    c = generator(resolution=64, seed=8)
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_maps_tile(generator):
    """Wrapping around an edge changes the normal no more than stepping inside the map does:
    the map tiles without a seam."""
    n = generator(resolution=256, seed=5).astype(np.float64)
    for axis in (0, 1):
        steps = np.abs(np.diff(n, axis=axis)).sum(-1)
        first = np.take(n, [0], axis=axis)
        last = np.take(n, [-1], axis=axis)
        seam = np.abs(first - last).sum(-1)
        assert seam.mean() <= 3.0 * steps.mean() + 1e-9


@pytest.mark.parametrize("generator_name", ["bumps", "nacre"])
def test_maps_generate_quickly(generator_name):
    """A 512² map with default settings generates in well under a second."""
    make = GENERATORS[generator_name]
    make(resolution=64)  # warm-up: imports, allocator
    start = time.perf_counter()
    make(resolution=512)
    assert time.perf_counter() - start < 1.0


# -- bumps -----------------------------------------------------------------------


def test_bumps_are_integrable_with_green_up():
    """The normals come from a height field with y toward row 0 (v up): the mixed partials of
    the height agree, which fails if the green channel points the other way."""
    n = normalmaps.bumps(resolution=256, seed=2)
    du, dv = _slopes(n)
    # Rows run toward -v, so ∂/∂v = -∂/∂row; columns run toward +u.
    d_du_dv = -(np.roll(du, -1, axis=0) - np.roll(du, 1, axis=0))
    d_dv_du = np.roll(dv, -1, axis=1) - np.roll(dv, 1, axis=1)
    curl = np.abs(d_dv_du - d_du_dv).mean()
    scale = np.abs(d_dv_du + d_du_dv).mean()
    assert curl < 0.05 * scale


def test_bumps_bulge_outward_green_up():
    """A single bump is raised: its right side tilts right (+x) and its top side (toward row 0)
    tilts up (+y)."""
    res = 128
    n = normalmaps.bumps(resolution=res, seed=4, count=1, radius=(0.2, 0.2))
    right = np.unravel_index(np.argmax(n[..., 0]), n.shape[:2])
    left = np.unravel_index(np.argmin(n[..., 0]), n.shape[:2])
    up = np.unravel_index(np.argmax(n[..., 1]), n.shape[:2])
    down = np.unravel_index(np.argmin(n[..., 1]), n.shape[:2])
    assert _wrapped(right[1] - left[1], res) > 0.1 * res
    assert _wrapped(up[0] - down[0], res) < -0.1 * res


@pytest.mark.parametrize("strength", [0.25, 1.0, 3.0])
def test_bumps_strength_is_the_steepest_slope(strength):
    """A lone bump's steepest slope equals strength."""
    n = normalmaps.bumps(resolution=512, seed=9, count=1, radius=(0.15, 0.15), strength=strength)
    du, dv = _slopes(n)
    assert np.hypot(du, dv).max() == pytest.approx(strength, rel=0.02)


def test_bumps_have_the_requested_size():
    """A lone bump of radius R tilts the normals over a disc of area π R²."""
    res, r = 256, 0.1
    n = normalmaps.bumps(resolution=res, seed=1, count=1, radius=(r, r))
    tilted = np.count_nonzero(n[..., 2] < 1.0) / res**2
    assert tilted == pytest.approx(math.pi * r * r, rel=0.05)


@pytest.mark.parametrize("args", [{"count": 0}, {"strength": 0.0}])
def test_bumps_can_be_flat(args):
    """No bumps, or zero strength, gives the flat map (0, 0, 1) everywhere."""
    n = normalmaps.bumps(resolution=32, **args)
    np.testing.assert_array_equal(n, np.broadcast_to([0.0, 0.0, 1.0], n.shape))


@settings(max_examples=25, deadline=None)
@given(
    resolution=st.integers(8, 96),
    seed=st.integers(0, 2**63 - 1),
    count=st.integers(0, 80),
    r_min=st.floats(0.001, 0.49),
    spread=st.floats(0.0, 1.0),
)
def test_bumps_any_settings_are_unit(resolution, seed, count, r_min, spread):
    """Any valid settings, including bumps wider than the map is tall, give finite unit normals
    facing out."""
    r_max = r_min + spread * (0.499 - r_min)
    n = normalmaps.bumps(resolution, seed, count, (r_min, r_max))
    assert np.isfinite(n).all() and n[..., 2].min() > 0.0
    np.testing.assert_allclose(np.linalg.norm(n.astype(np.float64), axis=-1), 1.0, atol=1e-6)


# -- nacre -----------------------------------------------------------------------


def test_nacre_cells_differ():
    """Without ripples each platelet is flat: there are several distinct normals, at most one
    per cell, and each covers a good part of the map."""
    cells = 40
    n = normalmaps.nacre(resolution=128, seed=3, cells=cells, ripple=0.0)
    distinct, counts = np.unique(n.reshape(-1, 3), axis=0, return_counts=True)
    assert cells // 2 <= len(distinct) <= cells
    assert counts.max() < 0.25 * n.shape[0] * n.shape[1]
    for slope in _slopes(distinct):
        assert len(np.unique(slope)) >= cells // 2, "both slope components vary per cell"
        assert slope.min() < 0.0 < slope.max(), "platelets tilt every way"


def test_nacre_tilt_is_the_largest_slope():
    """Without ripples no platelet is steeper than tilt, and some come close to it."""
    tilt = 0.5
    n = normalmaps.nacre(resolution=128, seed=5, cells=60, tilt=tilt, ripple=0.0)
    slope = np.hypot(*_slopes(n))
    assert slope.max() <= tilt * (1 + 1e-5)
    assert slope.max() > 0.8 * tilt


def test_nacre_ripples_are_concentric_growth_lines():
    """Without tilt the slope comes only from the ripples: at most ripple, and varying inside a
    cell (many distinct normals rather than one per cell)."""
    ripple = 0.1
    n = normalmaps.nacre(
        resolution=128, seed=5, cells=10, tilt=0.0, ripple=ripple, ripple_frequency=30.0
    )
    slope = np.hypot(*_slopes(n))
    assert slope.max() <= ripple * (1 + 1e-5)
    assert slope.max() > 0.9 * ripple
    assert len(np.unique(n.reshape(-1, 3), axis=0)) > 1000


@pytest.mark.parametrize(
    ("frequency", "kept"), [(16.0, 1.0), (24.0, 0.5), (32.0, 0.0), (90.0, 0.0)]
)
def test_nacre_fades_rings_the_texels_cannot_hold(frequency, kept):
    """Ripples are kept in full up to resolution/4 rings per width and fade out linearly to
    none at resolution/2 (Nyquist), so a small map shows no moiré."""
    n = normalmaps.nacre(
        resolution=64, seed=2, cells=6, tilt=0.0, ripple=0.2, ripple_frequency=frequency
    )
    assert np.hypot(*_slopes(n)).max() == pytest.approx(0.2 * kept, rel=0.05, abs=1e-7)


def test_nacre_flat_without_tilt_or_ripple():
    """With neither tilt nor ripple the map is flat."""
    n = normalmaps.nacre(resolution=32, tilt=0.0, ripple=0.0)
    np.testing.assert_array_equal(n, np.broadcast_to([0.0, 0.0, 1.0], n.shape))


# -- from_image --------------------------------------------------------------------


def test_from_image_decodes_and_renormalises(tmp_path):
    """Texels decode as 2c/255 - 1, renormalised, keeping the image's row order (row 0 = top)."""
    rgb = np.array([[[128, 128, 255], [255, 128, 128]], [[0, 0, 0], [10, 200, 90]]], np.uint8)
    path = tmp_path / "map.png"
    Image.fromarray(rgb).save(path)
    n = normalmaps.from_image(path)
    expected = 2.0 * rgb / 255.0 - 1.0
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    assert n.dtype == np.float32 and n.shape == (2, 2, 3)
    np.testing.assert_allclose(n, expected, atol=1e-6)


@pytest.mark.parametrize("mode", ["RGBA", "L", "P"])
def test_from_image_accepts_other_modes(tmp_path, mode):
    """Images with alpha, grey or a palette are read as RGB."""
    path = tmp_path / f"map-{mode}.png"
    Image.new("RGB", (4, 3), (128, 128, 255)).convert(mode).save(path)
    n = normalmaps.from_image(str(path))
    assert n.shape == (3, 4, 3)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-6)


def test_decode_keeps_zero_vectors_zero():
    """A texel that decodes to the zero vector stays (0, 0, 0) (the shader's "no map here"),
    never NaN."""
    n = normalmaps._decode(np.array([[[127.5, 127.5, 127.5], [127.5, 127.5, 255.0]]]), 255.0)
    assert np.isfinite(n).all()
    np.testing.assert_array_equal(n[0, 0], [0.0, 0.0, 0.0])
    np.testing.assert_allclose(n[0, 1], [0.0, 0.0, 1.0])


# -- build -----------------------------------------------------------------------


def test_build_none_is_none():
    """build("none") means no normal map."""
    assert normalmaps.build("none") is None


@pytest.mark.parametrize(
    ("kind", "args", "direct"),
    [
        ("bumps", {"resolution": 32, "seed": 4}, lambda: normalmaps.bumps(32, 4)),
        ("nacre", {"resolution": 32, "cells": 5}, lambda: normalmaps.nacre(32, cells=5)),
    ],
)
def test_build_dispatches(kind, args, direct):
    """build(kind, **args) gives the same map as calling the generator directly."""
    assert normalmaps.build(kind, **args).tobytes() == direct().tobytes()


def test_build_file(tmp_path):
    """build("file", path=...) reads the image."""
    path = tmp_path / "flat.png"
    Image.new("RGB", (2, 2), (128, 128, 255)).save(path)
    np.testing.assert_array_equal(
        normalmaps.build("file", path=str(path)), normalmaps.from_image(path)
    )


def test_build_unknown_kind():
    """An unknown map kind is a ValueError naming it and the known kinds."""
    with pytest.raises(ValueError, match=r"unknown normal map 'waves' \(known: none, bumps"):
        normalmaps.build("waves")


def test_build_unknown_argument_message():
    """An unknown argument is a ValueError naming the kind, the argument and the known ones."""
    with pytest.raises(ValueError) as info:
        normalmaps.build("bumps", size=3)
    assert str(info.value) == (
        "normal map 'bumps': unknown argument 'size' "
        "(known: resolution, seed, count, radius, strength)"
    )


@pytest.mark.parametrize(
    ("kind", "args", "bad"),
    [
        ("none", {"seed": 1}, "seed"),
        ("bumps", {"resolution": 4}, "resolution"),
        ("bumps", {"resolution": 64.0}, "resolution"),
        ("bumps", {"seed": -1}, "seed"),
        ("bumps", {"seed": "1"}, "seed"),
        ("bumps", {"count": -1}, "count"),
        ("bumps", {"radius": (0.2, 0.1)}, "radius"),
        ("bumps", {"radius": (0.0, 0.1)}, "radius"),
        ("bumps", {"radius": (0.1, 0.5)}, "radius"),
        ("bumps", {"radius": 0.1}, "radius"),
        ("bumps", {"radius": (0.1, 0.2, 0.3)}, "radius"),
        ("bumps", {"strength": float("nan")}, "strength"),
        ("bumps", {"strength": -1.0}, "strength"),
        ("nacre", {"cells": 0}, "cells"),
        ("nacre", {"tilt": -0.1}, "tilt"),
        ("nacre", {"ripple": float("inf")}, "ripple"),
        ("nacre", {"ripple_frequency": -1.0}, "ripple_frequency"),
        ("file", {}, "path"),
        ("file", {"path": 3}, "path"),
        ("file", {"path": "/nonexistent/normal-map.png"}, "path"),
    ],
)
def test_build_invalid_argument_names_it(kind, args, bad):
    """An out-of-range, ill-typed or missing argument is a ValueError naming kind and argument."""
    with pytest.raises(ValueError) as info:
        normalmaps.build(kind, **args)
    message = str(info.value)
    assert message.startswith(f"normal map '{kind}': ")
    assert f"'{bad}'" in message


def test_build_file_that_is_not_an_image(tmp_path):
    """A file Pillow cannot read is a ValueError naming the path argument."""
    path = tmp_path / "notes.png"
    path.write_text("not an image")
    with pytest.raises(ValueError, match="normal map 'file': argument 'path'"):
        normalmaps.build("file", path=str(path))
