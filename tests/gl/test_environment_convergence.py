"""Environment light's estimator converges to the integral it estimates: for a few
(n, t, v), ``environment_specular`` with ENV_BRUTE (the map read at level 0, as the
accuracy benchmark's reference) and 65 536 lobe samples agrees with a float64
quadrature of ∫ L(l)·f(l, v)·(n·l) dω over the map, f from opaline.model.reference.

The quadrature reads the map as the GPU does (bilinear at level 0, wrapping in
azimuth, clamped at the poles) on a grid of 2×2 points per texel, so it integrates the
very function the shader samples. Tolerance: 4 standard errors of the mean, the error
taken from the spread of 64 passes' means (each pass 1024 samples of the R2 sequence:
a quasi-random sequence's segments spread more than its whole converges, so this
over-states the error), plus 1e-3 of the case's brightest channel (fp32 sums and the
quadrature's sub-texel grid, both under 1e-3 measured).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.model import reference as ref
from opaline.model.params import Material
from opaline.scene.bright import split_bright
from opaline.scene.environments import resolve_map
from radiance_checks import is_radiance, radiance_problems

pytestmark = pytest.mark.gl

MAP = "studio"  # soft boxes with sharp edges: a lobe half on a panel is the hard case
SAMPLES, PASSES = 1024, 64
SUB = 2  # quadrature points per texel side
MATERIALS = {
    "glossy-300": Material(mdf="ashikhmin", ex=300.0, ey=300.0, kd=0.0),
    "rotation-100,1000": Material(mdf="ashikhmin", ex=100.0, ey=1000.0, theta1=0.5,
                                  theta2=1.0, kd=0.0),
    "thin-film-500": Material(iridescence="thin-film", ex=500.0, ey=500.0, kd=0.0,
                              film_ior=1.33, substrate_ior=1.0, film_thickness_min=250.0,
                              film_thickness_max=650.0),
    "multipeak": Material(mdf="multipeak", mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1,
                          theta2=0.2, kd=0.0),
}


def unit(x) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


# Normals up, level and toward the camera; views from near-normal to n·v ~ 0.6.
N = unit([[0.2, 0.9, 0.4], [0.0, 0.3, 1.0], [-0.6, 0.5, 0.6]])
T = unit(np.cross(N, [0.0, 1.0, 0.3]))
V = unit([[0.3, 0.6, 0.7], [0.0, 0.0, 1.0], [0.4, 0.1, 0.9]])


def bilinear(radiance: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The map at unit directions m (map frame) as textureLod(·, 0) reads it
    (environment_light.glsl's env_lookup; gl/background.py uploads rows flipped)."""
    height, width = radiance.shape[:2]
    rows = radiance[::-1]
    u = np.mod(np.arctan2(m[:, 2], m[:, 0]) / (2 * np.pi), 1.0)
    v = 0.5 + np.arcsin(np.clip(m[:, 1], -1.0, 1.0)) / np.pi
    x, y = u * width - 0.5, v * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    xa, xb = np.mod(x0.astype(int), width), np.mod(x0.astype(int) + 1, width)
    ya, yb = np.clip(y0.astype(int), 0, height - 1), np.clip(y0.astype(int) + 1, 0, height - 1)
    return ((rows[ya, xa] * (1 - fx) + rows[ya, xb] * fx) * (1 - fy)
            + (rows[yb, xa] * (1 - fx) + rows[yb, xb] * fx) * fy)


def sphere_grid(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """Directions (map frame) on a grid SUB times the map's, and their solid angles."""
    elevation = np.pi / 2 - (np.arange(height * SUB) + 0.5) * np.pi / (height * SUB)
    azimuth = (np.arange(width * SUB) + 0.5) * 2 * np.pi / (width * SUB)
    e, a = np.meshgrid(elevation, azimuth, indexing="ij")
    m = np.stack([np.cos(a) * np.cos(e), np.sin(e), np.sin(a) * np.cos(e)], -1)
    solid = (2 * np.pi / (width * SUB)) * (np.pi / (height * SUB)) * np.cos(e)
    return m.reshape(-1, 3), solid.reshape(-1)


def quadrature(mat: Material, radiance: np.ndarray, n, t, v, rotation: float) -> np.ndarray:
    """Σ L(m)·f(l, v)·max(n·l, 0)·Ω over the grid, l the object-frame direction of m."""
    m, solid = sphere_grid(*radiance.shape[:2])
    c, s = math.cos(rotation), math.sin(rotation)
    # env_to_map turns l into m = R l; here l = Rᵀ m.
    l = np.stack([c * m[:, 0] - s * m[:, 2], m[:, 1], s * m[:, 0] + c * m[:, 2]], -1)
    above = l @ n > 0.0
    l, m, solid = l[above], m[above], solid[above]
    shape = l.shape
    f = ref.reflected_radiance(mat, np.broadcast_to(n, shape), np.broadcast_to(t, shape), l,
                               np.broadcast_to(v, shape))
    result: np.ndarray = (bilinear(radiance, m) * f * solid[:, None]).sum(0)
    return result


@pytest.fixture(scope="module")
def radiance() -> np.ndarray:
    # The map as uploaded: a bright feature's excess is carried by lights, not the map.
    return split_bright(resolve_map(MAP, None))[0].astype(np.float64)


@pytest.mark.parametrize("rotation", [0.0, 1.3], ids=["turned=0", "turned=1.3"])
@pytest.mark.parametrize("name", list(MATERIALS))
def test_brute_force_estimate_converges_to_the_quadrature(renderer, radiance, name, rotation):
    mat = MATERIALS[name]
    uploaded = renderer.environments.get(MAP)
    environment = (uploaded.texture, uploaded.irradiance)
    passes = renderer.probes.lobe(mat, "specular", (N, T, V), environment, rotation=rotation,
                                  samples=SAMPLES, passes=PASSES)[..., :3].astype(np.float64)
    assert is_radiance(passes), radiance_problems(passes)
    estimate = passes.mean(0)
    error = passes.std(0, ddof=1) / math.sqrt(PASSES)
    expected = np.array([quadrature(mat, radiance, n, t, v, rotation)
                         for n, t, v in zip(N, T, V, strict=True)])
    bound = 4.0 * error + 1e-3 * expected.max(1, keepdims=True)
    off = np.abs(estimate - expected) / bound
    case, channel = np.unravel_index(int(off.argmax()), off.shape)
    assert off.max() <= 1.0, (
        f"case {case} channel {channel}: estimate {estimate[case, channel]:.6g}, quadrature "
        f"{expected[case, channel]:.6g} ± {bound[case, channel]:.3g}")
    # The bound is not loose: the estimate is within 2 % of every case's brightest channel.
    assert np.all(np.abs(estimate - expected) <= 0.02 * expected.max(1, keepdims=True))
