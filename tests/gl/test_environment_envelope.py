"""The multi-peak lobe under an environment (ENV_ENVELOPE, opaline.model.envelope): the
GLSL envelope and band filter agree with their float64 twins, and the whole estimator,
envelope plus shared-spectrum band samples, converges to the integral of the BRDF under
a constant map, where the envelope's irradiance is exact (so a wrong normalisation of
the bands or the envelope shows)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.gl.environment_maps import EnvironmentMaps
from opaline.model import irradiance as irr
from opaline.model import reference as ref
from opaline.model.params import Material
from stability_cases import as_f32

pytestmark = pytest.mark.gl

TWO_PI = 2.0 * math.pi


MULTIPEAK = Material(mdf="multipeak", mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1, theta2=0.2,
                     ks=0.7, kd=0.0)


@pytest.mark.parametrize("f0", [1.0, 0.3], ids=["no-fresnel", "f0=0.3"])
@pytest.mark.parametrize("rotation", [0.0, 2.0])
def test_multipeak_envelope_agrees(renderer, f0, rotation):
    """specular_envelope (the multi-peak lobe's envelope, ENV_ENVELOPE) is the twin's
    ks·A(n·v)·(1 + the bands' mean)·E(d)/π, d = envelope.dominant(n, v) turned into the
    map's frame."""
    from opaline.model import envelope

    rng = np.random.default_rng(9)
    n = rng.normal(size=(512, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = n + rng.normal(size=(512, 3)) * 0.8
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    keep = (n * v).sum(1) > 0.02
    n, v = as_f32(n[keep]), as_f32(v[keep])
    mat = MULTIPEAK.model_copy(update={"f0": f0})
    uploaded = renderer.environments.get("studio")
    environment = (uploaded.texture, uploaded.irradiance)
    gl = renderer.probes.lobe(mat, "envelope", (n, n, v), environment, rotation=rotation,
                              samples=0, brute=False, wavelengths=16)[0][:, :3]
    d = envelope.dominant(n.astype(np.float64), v.astype(np.float64))
    c, s = math.cos(rotation), math.sin(rotation)
    m = np.stack([c * d[:, 0] + s * d[:, 2], d[:, 1], c * d[:, 2] - s * d[:, 0]], -1)
    nv = (n.astype(np.float64) * v).sum(1)
    mean = envelope.band_mean(mat.mu_f, mat.alpha, mat.beta, envelope.cell_side(1))
    expected = (mat.ks * envelope.albedo(nv, f0)[:, None] * (1.0 + mean)
                * irr.irradiance(environment[1], m) / math.pi)
    assert np.isfinite(gl).all()
    assert float(np.abs(gl - expected).max()) <= 1e-5 * float(expected.max())


@pytest.mark.parametrize("cell", [0.0, 0.02, 0.3, 1.77])
def test_multipeak_band_filter_agrees(renderer, cell):
    """multipeak_band_cell is envelope.band_cell over the disc, to fp32's phase: the
    phase is reduced to cycles' fraction before the cosine (|Δcos| ≤ 2π·mu_f·r·1.2e-7)."""
    from opaline.model import envelope

    u = np.random.default_rng(11).random((4096, 2))
    r, phi = np.sqrt(u[:, 0]), TWO_PI * u[:, 1]
    h = as_f32(np.stack([r * np.cos(phi), r * np.sin(phi), np.full_like(r, cell)], -1))
    gl = renderer.probes.lobe(MULTIPEAK, "band_cell", (h, h[:, [2, 2, 2]]))[0][:, 0]
    hx, hy = h[:, 0].astype(np.float64), h[:, 1].astype(np.float64)
    expected = envelope.band_cell(hx, hy, 8.5, 2.0, 1.2, float(np.float32(cell)))
    assert float(np.abs(gl - expected).max()) <= 2e-4


# Slow bands (mu_f·r ≤ 0.25 cycles): the band term is half the lobe's energy, and the
# filter over 2048 samples' cells leaves them whole (sinc within 1e-3 of 1).
SLOW = Material(mdf="multipeak", mu_f=0.25, alpha=1.0, beta=0.3, theta1=0.4, theta2=0.9,
                ks=1.0, kd=0.0)
N_THETA, N_PHI = 400, 800


def hemisphere_integral(mat: Material, n, t, v, wavelengths: int) -> np.ndarray:
    """∫ f(l, v)·(n·l) dω over the hemisphere about n, on a (θ, φ) grid of l."""
    theta = (np.arange(N_THETA) + 0.5) * (0.5 * math.pi / N_THETA)
    phi = (np.arange(N_PHI) + 0.5) * (TWO_PI / N_PHI)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    frame = ref.shading_frame(np.asarray(n, float), np.asarray(t, float))
    local = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    l = (local[..., :1] * frame[0] + local[..., 1:2] * frame[1] + local[..., 2:] * frame[2])
    shape = l.shape
    f = ref.reflected_radiance(mat, np.broadcast_to(n, shape), np.broadcast_to(t, shape), l,
                               np.broadcast_to(v, shape), wavelengths)
    solid = np.sin(th) * (0.5 * math.pi / N_THETA) * (TWO_PI / N_PHI)
    result: np.ndarray = (f * solid[..., None]).sum((0, 1))
    return result


def grey_map_passes(renderer, tmp_path, mat: Material, level: float, passes: int):
    """The lobe probe's specular estimate at three (n, t, v) under a constant map:
    (passes, 3, 4), and the cases."""
    import cv2

    cv2.imwrite(str(tmp_path / "grey.hdr"), np.full((32, 64, 3), level, dtype=np.float32))
    n = np.array([[0.0, 0.0, 1.0], [0.3, 0.2, 0.93], [0.0, 0.6, 0.8]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t = np.cross(n, [0.0, 1.0, 0.3])
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    v = np.array([[0.2, 0.1, 0.97], [0.5, -0.2, 0.84], [-0.4, 0.5, 0.77]])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    maps = EnvironmentMaps(renderer.ctx, tmp_path)
    try:
        uploaded = maps.get("grey.hdr")
        return renderer.probes.lobe(mat, "specular", (as_f32(n), as_f32(t), as_f32(v)),
                                    (uploaded.texture, uploaded.irradiance), samples=4,
                                    passes=passes, brute=False, wavelengths=16), (n, t, v)
    finally:
        maps.release()


def test_split_estimate_converges_under_a_constant_map(renderer, tmp_path):
    level = 0.5
    passes, (n, t, v) = grey_map_passes(renderer, tmp_path, SLOW, level, 512)
    estimate = passes[..., :3].astype(np.float64).mean(0)
    error = passes[..., :3].std(0, ddof=1) / math.sqrt(passes.shape[0])
    expected = level * np.array([hemisphere_integral(SLOW, *case, 16)
                                 for case in zip(n, t, v, strict=True)])
    assert np.isfinite(passes).all()
    bound = 4.0 * error + 5e-3 * expected.max(1, keepdims=True)
    assert np.all(np.abs(estimate - expected) <= bound), (estimate, expected, bound)


@pytest.mark.parametrize("update", [{"mu_f": 0.0}, {"alpha": 0.0, "beta": 0.0}],
                         ids=["mu_f=0", "alpha=beta=0"])
def test_a_constant_band_is_the_envelope_s_and_leaves_no_grain(renderer, tmp_path, update):
    """With no phase (mu_f = 0, or α = β = 0) the band is a constant 1 and D = hz: its mean
    goes to the envelope and the samples carry nothing, so every pass gives the same
    estimate, the integral under a constant map. (Sampling the constant drew the colour
    noise a review found on the sphere at mu_f = 0 in the studio, even at high.)"""
    from opaline.model import envelope

    mat = SLOW.model_copy(update=update)
    assert envelope.band_mean(mat.mu_f, mat.alpha, mat.beta) == 1.0
    level = 0.5
    passes, (n, t, v) = grey_map_passes(renderer, tmp_path, mat, level, 8)
    rgb = passes[..., :3].astype(np.float64)
    assert float(np.abs(rgb - rgb[0]).max()) <= 1e-6 * float(np.abs(rgb).max())
    expected = level * np.array([hemisphere_integral(mat, *case, 16)
                                 for case in zip(n, t, v, strict=True)])
    np.testing.assert_allclose(rgb[0], expected, rtol=5e-3)
