"""Environment light's GLSL agrees with its float64 twins, case by case, through
glsl/lobe_probe.glsl: the A-S sampler and the projected disc (lib/lobe_sampling.glsl),
the rotation source's three-lobe mixture (``env_sample_half``) and the SH9 irradiance
(``environment_irradiance``), over exponents 0 … 1e6 and θ in ±2π.

Tolerances (fp32, unit roundoff 6e-8):
* a sample's half vector within 1e-3 of its lobe's angular width (1/√(e + 1)) of the
  twin's, plus 1e-6: what a filtered map read can tell apart is far coarser, and
  ``1 - u`` for u < 1e-4 keeps only a few digits in fp32 (GLSL has no log1p), which
  moves those samples by a fraction of their tiny distance from the pole;
* its density within 2e-3 relative (the BRDF probe's tolerance, stability_cases), plus
  what fp32 cannot know near the horizon: D = norm·hz^e is computed from s² = hx² + hy²,
  rounded by ~1.2e-7, so ln D moves by e·0.6e-7/hz² (a sample lands there with
  probability ≤ hz^(e+1));
* irradiance within 1e-5 of the largest value: nine terms of fp32 products.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.gl.environment_maps import EnvironmentMaps
from opaline.model import irradiance as irr
from opaline.model import lobe_sampling as ls
from opaline.model.params import Material
from stability_cases import as_f32

pytestmark = pytest.mark.gl

TWO_PI = 2.0 * math.pi
EXPONENTS = {
    "ex=ey=0": (0.0, 0.0), "ex=ey=1e-6": (1e-6, 1e-6), "ex=ey=10": (10.0, 10.0),
    "ex=100,ey=10": (100.0, 10.0), "ex=ey=1e3": (1e3, 1e3), "ex=ey=1e6": (1e6, 1e6),
    "ex=0,ey=1e6": (0.0, 1e6), "ex=1e6,ey=0": (1e6, 0.0), "ex=1e6,ey=1": (1e6, 1.0),
    "ex=1e6,ey=1e-6": (1e6, 1e-6),
}
THETAS = {"0.3,-1": (0.3, -1.0), "2pi,-2pi": (TWO_PI, -TWO_PI), "-3pi/2,pi": (-1.5 * math.pi, math.pi),
          "1e-6,pi/2": (1e-6, math.pi / 2)}
H_RTOL, H_ATOL = 1e-3, 1e-6
PDF_RTOL = 2e-3
S2_ROUNDING = 1.2e-7


def cases() -> np.ndarray:
    """Random u in [0, 1)³ and every corner of the sampler's branches (quadrant edges,
    u → 1, u tiny), float32 as the GPU gets them."""
    u = np.random.default_rng(21).random((2048, 3))
    edges = np.array([0.0, 1e-7, 0.25 - 2.0 ** -26, 0.25, 0.5, 0.75, 1.0 - 2.0 ** -24])
    corners = np.stack(np.meshgrid(edges, edges, edges[[0, 3, 4, 6]], indexing="ij"), -1)
    return as_f32(np.concatenate([u, corners.reshape(-1, 3)]))


def material(ex: float, ey: float, thetas=(0.0, 0.0), **fields) -> Material:
    return Material(mdf="ashikhmin", ex=ex, ey=ey, theta1=thetas[0], theta2=thetas[1], **fields)


def exponent_at(h: np.ndarray, ex: float, ey: float) -> np.ndarray:
    s2 = np.maximum(h[:, 0] ** 2 + h[:, 1] ** 2, 1e-300)
    return (ex * h[:, 0] ** 2 + ey * h[:, 1] ** 2) / s2


def check_samples(gl: np.ndarray, h: np.ndarray, pdf: np.ndarray, u: np.ndarray,
                  e: np.ndarray, e_pdf: np.ndarray | None = None) -> None:
    """``e``: the exponent of each case's lobe along its sample, ``e_pdf`` the largest
    exponent its density reads (the mixture's: another lobe's, default ``e``)."""
    assert np.isfinite(gl).all() and (gl[:, 3] >= 0).all()
    width = 1.0 / np.sqrt(e + 1.0)
    e = e if e_pdf is None else e_pdf
    dh = np.linalg.norm(gl[:, :3] - h, axis=1)
    bad = dh > H_RTOL * width + H_ATOL
    assert not bad.any(), f"{bad.sum()} half vectors off, e.g. u {u[bad][:3]}: {dh[bad][:3]}"
    hz2 = np.maximum(h[:, 2] ** 2, 1e-30)
    rtol = PDF_RTOL + e * 0.5 * S2_ROUNDING / hz2
    err = np.abs(gl[:, 3] - pdf) / (rtol * pdf + 1e-30)
    worst = int(err.argmax())
    assert err[worst] <= 1.0, (f"pdf off at u {u[worst]}: gl {gl[worst, 3]:.7g} twin "
                               f"{pdf[worst]:.7g} ({err[worst]:.3g}× the tolerance)")


@pytest.mark.parametrize("ex,ey", EXPONENTS.values(), ids=EXPONENTS.keys())
def test_ashikhmin_sampler_agrees(renderer, ex, ey):
    u = cases()
    gl = renderer.probes.lobe(material(ex, ey), "ashikhmin", (u,))[0].astype(np.float64)
    h, pdf = ls.sample_ashikhmin(u[:, :2], ex, ey)
    check_samples(gl, h, pdf, u, exponent_at(h, ex, ey))


def test_disc_sampler_agrees(renderer):
    u = cases()
    gl = renderer.probes.lobe(Material(mdf="multipeak"), "disc", (u,))[0].astype(np.float64)
    h, pdf = ls.sample_projected_disc(u[:, :2])
    check_samples(gl, h, pdf, u, np.zeros(len(u)))


@pytest.mark.parametrize("thetas", THETAS.values(), ids=THETAS.keys())
@pytest.mark.parametrize("ex,ey", [(100.0, 10.0), (1e3, 1e3), (1e6, 1.0), (0.0, 1e6)],
                         ids=["ex=100,ey=10", "ex=ey=1e3", "ex=1e6,ey=1", "ex=0,ey=1e6"])
def test_rotation_mixture_agrees(renderer, ex, ey, thetas):
    u = cases()
    mat = material(ex, ey, thetas)
    gl = renderer.probes.lobe(mat, "mixture", (u,))[0].astype(np.float64)
    h, pdf = ls.rotated_mixture(u, ex, ey, (0.0, mat.theta1, mat.theta2))
    unrotated, _ = ls.sample_ashikhmin(u[:, :2], ex, ey)  # the sample in its lobe's frame
    check_samples(gl, h, pdf, u, exponent_at(unrotated, ex, ey), np.full(len(u), max(ex, ey)))


@pytest.mark.parametrize("ex,ey", [(1e6, 1e6), (100.0, 10.0)])
def test_thin_film_and_multipeak_sample_their_own_lobe(renderer, ex, ey):
    """env_sample_half: a thin film samples its one unrotated A-S lobe, multi-peak the disc."""
    u = cases()
    film = Material(iridescence="thin-film", ex=ex, ey=ey)
    gl = renderer.probes.lobe(film, "mixture", (u,))[0].astype(np.float64)
    h, pdf = ls.sample_ashikhmin(u[:, :2], ex, ey)
    check_samples(gl, h, pdf, u, exponent_at(h, ex, ey))
    gl = renderer.probes.lobe(Material(mdf="multipeak"), "mixture", (u,))[0].astype(np.float64)
    h, pdf = ls.sample_projected_disc(u[:, :2])
    check_samples(gl, h, pdf, u, np.zeros(len(u)))


def test_sequence_agrees_at_every_sample_index(renderer):
    """env_sequence(k) is the twin's R2 point at any k a pixel reaches (4096 samples,
    a tier's most, up to the probe's 2^18): within 2e-7 plus k·2.4e-10, the 32-bit
    fixed-point rounding of the R2 constants."""
    k = np.concatenate([np.arange(64), np.geomspace(64, 2 ** 18, 200).astype(int), [4095]])
    shift = as_f32(np.random.default_rng(8).random((len(k), 3)))
    cases = (np.stack([k, k, k], -1).astype(np.float64), shift)
    gl = renderer.probes.lobe(material(1.0, 1.0), "sequence", cases)[0][:, :3]
    expected = ls.sequence(k, shift)
    diff = np.abs(gl - expected)
    diff = np.minimum(diff, 1.0 - diff)  # the unit interval wraps
    bound = 2e-7 + k[:, None] * 2.4e-10
    worst = int((diff / bound).max(1).argmax())
    assert np.all(diff <= bound), f"k = {k[worst]}: gl {gl[worst]}, twin {expected[worst]}"


@pytest.mark.parametrize("name", ["studio", "sky"])
@pytest.mark.parametrize("rotation,intensity", [(0.0, 1.0), (2.0, 0.25), (-TWO_PI, 1000.0)])
def test_irradiance_agrees(renderer, name, rotation, intensity):
    """environment_irradiance(n) is the twin's at n turned into the map's frame, scaled."""
    d = np.random.default_rng(5).normal(size=(512, 3))
    n = as_f32(np.concatenate([d / np.linalg.norm(d, axis=1, keepdims=True),
                               np.eye(3), -np.eye(3)]))
    uploaded = renderer.environments.get(name)
    environment = (uploaded.texture, uploaded.irradiance)
    gl = renderer.probes.lobe(material(10.0, 10.0), "irradiance", (n,), environment,
                              rotation=rotation, intensity=intensity)[0][:, :3]
    c, s = math.cos(rotation), math.sin(rotation)
    m = np.stack([c * n[:, 0] + s * n[:, 2], n[:, 1], c * n[:, 2] - s * n[:, 0]], -1)
    expected = irr.irradiance(environment[1], m) * intensity
    assert np.isfinite(gl).all() and (gl >= 0).all()
    assert float(np.abs(gl - expected).max()) <= 1e-5 * float(expected.max())


def test_irradiance_of_a_users_constant_map(renderer, tmp_path):
    """A file's map goes through the same upload and coefficients: constant L gives π·L."""
    import cv2

    cv2.imwrite(str(tmp_path / "grey.hdr"), np.full((32, 64, 3), 0.5, dtype=np.float32))
    maps = EnvironmentMaps(renderer.ctx, tmp_path)
    try:
        uploaded = maps.get("grey.hdr")
        environment = (uploaded.texture, uploaded.irradiance)
        n = as_f32(np.concatenate([np.eye(3), -np.eye(3)]))
        gl = renderer.probes.lobe(material(0.0, 0.0), "irradiance", (n,), environment)[0]
    finally:
        maps.release()
    np.testing.assert_allclose(gl[:, :3], np.pi * 0.5, rtol=1e-3)


@pytest.mark.parametrize("f0", [1.0, 0.2], ids=["no-fresnel", "f0=0.2"])
def test_rotation_map_samples_in_rgb_are_the_papers_channels(renderer, f0):
    """With ENV_RGB_LOBES a spectral variant's map samples give what the paper's RGB
    variant gives for the same samples (its lights stay spectral): the channels' lobes
    are the mixture's own terms, not evaluated again."""
    rng = np.random.default_rng(12)
    n = rng.normal(size=(256, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t = np.cross(n, [0.0, 1.0, 0.3])
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    v = n + rng.normal(size=(256, 3)) * 0.5
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    cases = (as_f32(n), as_f32(t), as_f32(v))
    mat = material(100.0, 1000.0, (0.5, 1.0), ks=0.6, kd=0.0, f0=f0)
    uploaded = renderer.environments.get("studio")
    environment = (uploaded.texture, uploaded.irradiance)
    common = dict(samples=9, passes=2, brute=False)
    rgb = renderer.probes.lobe(mat, "specular", cases, environment, **common)
    shared = renderer.probes.lobe(mat, "specular", cases, environment, wavelengths=16,
                                  rgb_lobes=True, **common)
    spectral = renderer.probes.lobe(mat, "specular", cases, environment, wavelengths=16,
                                    **common)
    assert np.isfinite(shared).all() and float(rgb[..., :3].max()) > 0.0
    # To fp32: the RGB variant forms h again from l + v, where a lobe of exponent 1000
    # turns its last bits into ~1e-3 of a sample's weight.
    diff = np.abs(shared - rgb)
    assert float(diff.max()) <= 1e-3 * float(rgb.max()) and float(diff.mean()) <= 1e-6
    assert not np.allclose(spectral, rgb, rtol=1e-3)  # the define is what makes them equal


@pytest.mark.parametrize("lod", [0.25, 0.5, 0.75])
def test_a_map_read_takes_one_level_with_trilinear_odds(renderer, tmp_path, lod):
    """env_lookup reads one mip level, floor(lod) or the next, the upper with probability
    fract(lod): trilinear in expectation at one bilinear read's cost. A checkerboard of 0
    and 1 has level 1 at 0.5 everywhere, so at a level-0 texel's centre each read is the
    texel or 0.5, and the share of 0.5 is fract(lod). (The trilinear read gave every pixel
    the mix: it fails on the read between the two.)"""
    import cv2

    height, width = 64, 128  # the smallest a file is read at (environment_files.fit)
    rows, cols = np.indices((height, width))
    checker = ((rows + cols) % 2).astype(np.float32)
    cv2.imwrite(str(tmp_path / "checker.hdr"), np.repeat(checker[..., None], 3, axis=2))
    rng = np.random.default_rng(21)
    count = 8192
    i = rng.integers(0, width, count)
    j = rng.integers(4, height - 4, count)  # away from the poles' squeezed texels
    azimuth = TWO_PI * (i + 0.5) / width
    elevation = ((j + 0.5) / height - 0.5) * math.pi
    m = np.stack([np.cos(elevation) * np.cos(azimuth), np.sin(elevation),
                  np.cos(elevation) * np.sin(azimuth)], -1)
    maps = EnvironmentMaps(renderer.ctx, tmp_path)
    try:
        uploaded = maps.get("checker.hdr")
        environment = (uploaded.texture, uploaded.irradiance)

        def read(level: float) -> np.ndarray:
            cases = (as_f32(m), as_f32(np.full((count, 3), level)), as_f32(np.zeros((count, 3))))
            return renderer.probes.lobe(material(1.0, 1.0), "lookup", cases, environment,
                                        brute=False)[0][:, 0].astype(np.float64)

        texel = read(0.0)
        mixed = read(lod)
    finally:
        maps.release()
    assert np.all(np.minimum(np.abs(texel), np.abs(texel - 1.0)) < 1e-2)  # level 0: the texels
    upper = np.abs(mixed - 0.5) < 1e-2
    lower = np.abs(mixed - texel) < 1e-2
    assert np.all(upper | lower), "a read between two levels' values: trilinear, not one level"
    share = float(upper[np.abs(texel - 0.5) > 0.25].mean())
    assert abs(share - lod) < 0.03, share
