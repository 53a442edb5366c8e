"""A grating's orders read from the map (glsl/lib/environment_grating.glsl) agree with
their float64 twin (model/grating_environment.py), case by case through
glsl/lobe_probe.glsl: on a smooth map of a user's, read at level 0, so the twin can read
it in closed form, every pixel cutting the orders' curve at its own offset
(``lobe_sampling.pixel_shift``) and each pass at the next; and a grating's render under
the studio has its colour where the orders send the light, never a non-finite pixel.

Tolerance: 1 % of the largest value, for fp32 and for the map's bilinear reads of a
function the twin evaluates exactly (its curvature over a texel of 128 × 64 is ~1e-3)."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl.environment_maps import EnvironmentMaps
from opaline.model import grating_environment as ge
from opaline.model.cielab import chroma, srgb_to_lab
from opaline.model.environment_light import reads_orders
from opaline.model.lobe_sampling import pixel_shift
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import get_preset
from opaline.model.reference import shading_frame
from opaline.model.request import resolve
from stability_cases import as_f32

pytestmark = pytest.mark.gl

GOLDEN = 0.6180339887
WIDTH, HEIGHT = 128, 64


def radiance_uv(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A smooth map with no bright feature (nothing split off as a light): colour changing
    with azimuth and elevation both, so a read in the wrong direction reads another."""
    u, v = np.broadcast_arrays(u, v)
    return np.stack([0.5 + 0.4 * np.sin(2.0 * np.pi * u), 0.5 + 0.4 * np.cos(np.pi * v),
                     0.2 + 0.6 * v * v], axis=-1)


def radiance_toward(d: np.ndarray) -> np.ndarray:
    u = np.mod(np.arctan2(d[..., 2], d[..., 0]) / (2.0 * np.pi), 1.0)
    v = 0.5 + np.arcsin(np.clip(d[..., 1], -1.0, 1.0)) / np.pi
    return radiance_uv(u, v)


@pytest.fixture
def smooth_map(renderer, tmp_path):
    import cv2

    u = (np.arange(WIDTH) + 0.5) / WIDTH
    v = 1.0 - (np.arange(HEIGHT) + 0.5) / HEIGHT  # row 0 is the zenith
    rgb = radiance_uv(u[None, :], v[:, None]).astype(np.float32)
    cv2.imwrite(str(tmp_path / "smooth.hdr"), rgb[..., ::-1])
    maps = EnvironmentMaps(renderer.ctx, tmp_path)
    try:
        uploaded = maps.get("smooth.hdr")
        assert len(uploaded.light_directions) == 0
        yield uploaded.texture, uploaded.irradiance
    finally:
        maps.release()


def grating(pitch: float, orders: int, depth: float, ey: float) -> Material:
    return Material(iridescence="grating", mdf="ashikhmin", ex=3000.0, ey=ey, ks=0.7, kd=0.0,
                    f0=0.9, grating_pitch=pitch, grating_orders=orders, grating_depth=depth)


def cases(count: int = 512) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(23)
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t = rng.normal(size=(count, 3))
    v = n + rng.normal(size=(count, 3)) * 0.6
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return as_f32(n), as_f32(t), as_f32(v)


@pytest.mark.parametrize("pitch,orders,depth,ey", [(1.6, 3, 150.0, 30000.0),
                                                   (0.74, 2, 120.0, 30000.0),
                                                   (1.0, 8, 400.0, 300.0)],
                         ids=["cd", "dvd", "deep-8-orders-broad"])
def test_orders_read_from_the_map_agree_with_their_twin(renderer, smooth_map, pitch, orders,
                                                       depth, ey):
    material = grating(pitch, orders, depth, ey)
    n, t, v = cases()
    reads, passes = 3, 2
    gl = renderer.probes.lobe(material, "specular", (n, t, v), smooth_map, passes=passes,
                              brute=True, wavelengths=16, grating_reads=reads)[..., :3]
    frame = shading_frame(n.astype(np.float64), t.astype(np.float64))
    basis = np.stack(frame, axis=-2)  # (count, 3 axes, 3): rows t, b, n
    vl = np.einsum("cij,cj->ci", basis, v.astype(np.float64))
    index = np.arange(len(n))
    shift = pixel_shift(index % 256, index // 256)[:, 0]

    def radiance_of(case: int):
        return lambda l_local, solid_angle: radiance_toward(l_local @ basis[case])

    assert np.isfinite(gl).all() and float(gl.max()) > 0.0
    scale = float(gl.max())
    twins = []
    for k in range(passes):
        offset = np.mod(shift + k * GOLDEN, 1.0)
        twins.append(np.stack([ge.environment_grating(material, vl[c], radiance_of(c),
                                                      reads, offset[c])
                               for c in range(len(n))]))
        assert float(np.abs(gl[k] - twins[-1]).max()) <= 1e-2 * scale
    # Read at the mip level of each piece's footprint (the renderer's reads): on this
    # smooth map the filtered reads stay within 5 % of the largest value, on average
    # within 1 %: a footprint read levels too coarse would average the map's colours away.
    filtered = renderer.probes.lobe(material, "specular", (n, t, v), smooth_map,
                                    passes=passes, brute=False, wavelengths=16,
                                    grating_reads=reads)[..., :3]
    error = np.abs(filtered - np.stack(twins))
    assert float(error.max()) <= 0.05 * scale and float(error.mean()) <= 0.01 * scale


def test_a_cd_under_the_studio_shows_its_orders(renderer):
    """cd-rom-grating under the studio at standard, the path a user's request takes:
    finite, and its orders colour the disc: mean C*ab over it several times the same
    disc's with grooves of no depth (a grey mirror: the order 0 only)."""
    preset = get_preset("cd-rom-grating")

    def disc_chroma(**fields) -> float:
        job = resolve(RenderRequest(preset="cd-rom-grating", width=96, height=96,
                                    environment="studio", format="png16", **fields), preset)
        assert reads_orders(job)
        image = renderer.render(job, preset=preset).display[..., :3]
        assert np.isfinite(image).all()
        covered = np.abs(image - image[0, 0]).max(-1) > 1e-3
        return float(chroma(srgb_to_lab(image))[covered].mean())

    grooved, flat = disc_chroma(), disc_chroma(grating_depth=0.0)
    assert grooved > 3.0 * flat, (grooved, flat)


def test_the_orders_read_from_the_map_sum_a_shorter_series(renderer):
    """Where a grating's orders are read from the map, J_m's series is cut at
    READS_SERIES_TOLERANCE (7 terms at the CD's 150 nm); under its key light, where the
    shading is checked against its twin to 1e-6, at SERIES_TOLERANCE (9)."""
    from opaline.model.grating import READS_SERIES_TOLERANCE, bessel_terms

    preset = get_preset("cd-rom-grating")
    seen: set = set()
    renderer.programs.record = seen
    try:
        for environment in ("studio", None):
            job = resolve(RenderRequest(preset="cd-rom-grating", width=16, height=16,
                                        environment=environment), preset)
            renderer.render(job, preset=preset)
    finally:
        renderer.programs.record = None
    terms = {bool(dict(defines).get("ENV_GRATING_ORDERS")): dict(defines)["BESSEL_TERMS"]
             for name, defines in seen if name == "surface.glsl"}
    assert terms == {True: bessel_terms(150.0, READS_SERIES_TOLERANCE),
                     False: bessel_terms(150.0)} == {True: 7, False: 9}


def test_the_series_length_is_the_materials_define_alone():
    """The surface program's BESSEL_TERMS comes from the material's defines, which know
    whether the orders are read from the map: no later define set has to override it
    (the brute-force reference samples the whole lobe and sums the key light's series)."""
    from opaline.gl.material_program import surface_defines

    preset = get_preset("cd-rom-grating")

    def terms(environment: str | None, brute: bool = False) -> int | bool:
        job = resolve(RenderRequest(preset="cd-rom-grating", environment=environment), preset)
        return surface_defines(job, preset, brute)["BESSEL_TERMS"]

    assert (terms("studio"), terms("studio", brute=True), terms(None)) == (7, 9, 9)
