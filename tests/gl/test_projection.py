"""Presets on a user's mesh: the object-space (triplanar) projection of their maps, its
float64 twin, and what a preset shows on a real scan without UVs (tests/assets)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opaline.model import projection

BUNNY = Path(__file__).parents[1] / "assets" / "bunny.ply"


def test_weights_are_a_partition_that_follows_the_normal():
    rng = np.random.default_rng(4)
    n = rng.normal(size=(500, 3))
    w = projection.weights(n / np.linalg.norm(n, axis=1, keepdims=True))
    assert np.allclose(w.sum(axis=1), 1.0)
    assert np.all(np.argmax(w, axis=1) == np.argmax(np.abs(n), axis=1))
    assert np.allclose(projection.weights(np.array([[0.0, -1.0, 0.0]])), [[0, 1, 0]])
    assert np.allclose(projection.weights(np.zeros((1, 3))), 1 / 3)


def test_flat_map_keeps_the_geometric_normal():
    """Whiteout with (0, 0, 1) in every plane gives back n, on either side of every axis."""
    rng = np.random.default_rng(5)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    flat = np.tile([0.0, 0.0, 1.0], (200, 1))
    out = projection.whiteout(flat, flat, flat, n, projection.weights(n))
    assert np.allclose(out, n, atol=1e-12)


def test_frame_puts_one_tile_across_the_longest_side():
    origin, scale = projection.frame(np.array([[1.0, -2.0, 0.0], [3.0, 2.0, 0.5]]))
    assert origin == (1.0, -2.0, 0.0) and scale == pytest.approx(0.25)
    assert projection.projects("auto", np.zeros((4, 2)))
    assert not projection.projects("auto", np.array([[0.0, 0.0], [0.5, 1.0]]))
    assert projection.projects("object", np.array([[0.0, 0.0], [0.5, 1.0]]))


def smooth_map(size: int = 64) -> np.ndarray:
    """A tiling RGBA map: a tangent-space normal map of a smooth bump field, and a scalar."""
    u, v = np.meshgrid((np.arange(size) + 0.5) / size, (np.arange(size) + 0.5) / size)
    dx, dy = 0.4 * np.cos(2 * np.pi * u), 0.3 * np.sin(2 * np.pi * (u + 2 * v))
    normal = np.stack([-dx, -dy, np.ones_like(u)], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    scalar = 0.5 + 0.5 * np.sin(2 * np.pi * (2 * u - v))
    return np.concatenate([normal, scalar[..., None]], axis=-1)


@pytest.mark.gl
def test_glsl_projection_matches_reference(renderer):
    """lib/triplanar.glsl (weights, planes, whiteout blend, scalar blend) against the twin."""
    rng = np.random.default_rng(21)
    q = rng.uniform(-2.0, 3.0, size=(2000, 3))
    n = rng.normal(size=(2000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n[:3] = [[0, 0, 1], [0, -1, 0], [0.6, 0.0, -0.8]]
    texels = smooth_map()
    gl = renderer.probes.triplanar(q, n, texels)
    normal, scalar = projection.sample(texels, q, n)
    assert np.all(np.isfinite(gl))
    # fp32 coordinates and GPUs' 8-bit bilinear weights on a map that changes ~0.04 a texel.
    assert float(np.abs(gl[:, :3] - normal).max()) < 2e-3
    assert float(np.abs(gl[:, 3] - scalar).max()) < 2e-3


def film_chromaticity_spread(preset: str) -> float:
    """Std of the chromaticity (rgb over its sum) over the object's lit pixels, specular
    only (kd 0): how much the film's colour changes across the bunny. One constant film
    changes it only with the angles; a thickness field changes it from place to place."""
    from opaline import render
    from opaline.model.presets import all_presets

    base = {"preset": preset, "mesh": str(BUNNY), "width": 128, "height": 128}
    shaded = decode(render(base))
    back = np.round(np.array(all_presets()[preset].background) * 255.0) / 255.0
    on_object = np.abs(shaded - back).max(axis=-1) > 2.5 / 255.0
    film = decode(render({**base, "kd": 0.0}))
    total = film.sum(axis=-1)
    lit = on_object & (total > 0.15)
    assert lit.sum() > 500, "too little of the object is lit to measure"
    chromaticity = film[lit] / total[lit, None]
    return float(chromaticity.std(axis=0).mean())


def decode(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.float64) / 255.0


# Measured on tests/assets/bunny.ply at 128² (before the projection → with it):
# nacre-film 0.024 → 0.047, oil-film 0.026 → 0.093. (soap-bubble: 0.071 → 0.075, its
# constant film already changes colour with the angle: this measure cannot tell.)
@pytest.mark.gl
@pytest.mark.parametrize(("preset", "threshold"), [("nacre-film", 0.035), ("oil-film", 0.05)])
def test_film_thickness_varies_over_a_scan(preset, threshold):
    """nacre-film's tablets and oil-film's swirl reach a mesh without UVs (each was one
    constant film: the map read at uv 0 everywhere)."""
    spread = film_chromaticity_spread(preset)
    print(f"{preset}: chromaticity spread {spread:.4f}")
    assert spread > threshold


@pytest.mark.gl
def test_cd_tracks_are_concentric_on_a_mesh_with_uvs(tmp_path):
    """A CD preset's tangents stay concentric on a user's mesh, UVs or not (they followed
    the UVs before); the axis is the request's."""
    from mesh_helpers import mesh_bytes, torus_with_uvs
    from opaline import render

    path = tmp_path / "torus.obj"
    path.write_bytes(mesh_bytes("obj", torus_with_uvs()))
    base = {"preset": "cd-rom", "mesh": str(path), "width": 96, "height": 96}
    default = render(base)
    assert default == render({**base, "tangent_field": "concentric"})
    assert default != render({**base, "tangent_field": "uv"})
    assert default != render({**base, "tangent_axis": (1.0, 0.0, 0.0)})


def test_a_tangent_axis_with_no_direction_is_the_default():
    """Every schema-valid axis is accepted (schemathesis' positive data): one too short to
    have a direction means the default axis, as leaving it out does."""
    from opaline.local.api import as_request

    for axis in ((0, 0, 0), (5e-324, 0, 0), (1e-10, -1e-10, 0)):
        request = as_request({"preset": "cd-rom", "mesh": str(BUNNY), "tangent_axis": axis})
        assert request.tangent_axis is None, axis
    # A short one keeps its direction, as a unit vector (the default's is the default).
    kept = as_request({"preset": "cd-rom", "mesh": str(BUNNY), "tangent_axis": (1e-3, 0, 0)})
    assert kept.tangent_axis == (1.0, 0.0, 0.0)
    up = as_request({"preset": "cd-rom", "mesh": str(BUNNY), "tangent_axis": (0, 1e-3, 0)})
    assert up.tangent_axis is None
