"""The GLSL thin-film and grating sources agree with their float64 references (issue 14).

Tolerance: the stability suite's fp32 bound (tests/stability_cases.py),
|gl - ref| ≤ 2e-3·(|ref| + 1e-3·S) per case and channel, S the larger of max|ref|
and what the lobe reflects with R = 1; over 200 random parameter sets per source
(full ranges, lobe- and order-aimed geometry, all wavelength counts) and the grid
of every range's ends. Measured worst over the 200 sets: 0.003 of the bound for
the film, 0.35 for the grating (its orders' lobes at exponents near 1e6 are
narrower than fp32 resolves the shifted half vector); the bound is the suite's.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from opaline.model import reference as ref
from opaline.model.params import Material
from stability_cases import (
    DEGENERATE,
    check_probe,
    lobe_cases,
    probe_error,
    random_cases,
    stack,
    unit,
)

pytestmark = pytest.mark.gl

WAVELENGTH_CHOICES = (0, 0, 3, 16, 32, 128)
CASES = 48


def film_material(rng: np.random.Generator, **fixed) -> Material:
    thickness = float(rng.choice([0.0, rng.uniform(0.0, 2000.0)], p=[0.1, 0.9]))
    fields = dict(
        iridescence="thin-film",
        ex=float(10 ** rng.uniform(-3, 6)),
        ey=float(10 ** rng.uniform(-3, 6)),
        film_ior=float(rng.uniform(1.0, 3.0)),
        substrate_ior=float(rng.uniform(1.0, 4.0)),
        film_thickness_max=thickness,
        ks=float(rng.uniform(0.1, 2.0)),
    )
    return Material(**{**fields, **fixed})


def grating_material(rng: np.random.Generator, **fixed) -> Material:
    fields = dict(
        iridescence="grating",
        ex=float(10 ** rng.uniform(-1, 6)),
        ey=float(10 ** rng.uniform(-1, 6)),
        grating_pitch=float(10 ** rng.uniform(math.log10(0.2), math.log10(20.0))),
        grating_orders=int(rng.integers(1, 9)),
        grating_depth=float(rng.uniform(0.0, 400.0)),
        f0=float(rng.choice([1.0, rng.uniform(0.0, 1.0)])),
        ks=float(rng.uniform(0.1, 2.0)),
    )
    return Material(**{**fields, **fixed})


def order_cases(rng: np.random.Generator, material: Material, count: int):
    """Views that meet the grating equation (l + v)·b = m·λ/d for a random order and
    visible λ, offset by 1e-4 … 1e-1 in t and b: the orders' lobes, where they are bright."""
    n = unit(rng.normal(size=(8 * count, 3)))
    t_in = unit(rng.normal(size=(8 * count, 3)))
    t, b, n = ref.shading_frame(n, t_in)
    l_loc = unit(rng.normal(size=(8 * count, 3)) * [1, 1, 0] + [0, 0, 1.0])
    m = rng.integers(-material.grating_orders, material.grating_orders + 1, size=8 * count)
    lam = rng.uniform(380.0, 780.0, size=8 * count)
    off = 10.0 ** rng.uniform(-4, -1, size=(8 * count, 2)) * rng.choice([-1, 1], size=(8 * count, 2))
    vt = -l_loc[:, 0] + off[:, 0]
    vb = m * lam / (1000.0 * material.grating_pitch) - l_loc[:, 1] + off[:, 1]
    vn2 = 1.0 - vt * vt - vb * vb
    keep = np.flatnonzero(vn2 > 1e-4)[:count]
    vn = np.sqrt(np.maximum(vn2, 0.0))
    to_world = np.stack([t, b, n], axis=1)  # rows t, b, n: local → world is its transpose
    l = np.einsum("kij,ki->kj", to_world, l_loc)
    v = np.einsum("kij,ki->kj", to_world, np.stack([vt, vb, vn], axis=1))
    return n[keep], t_in[keep], l[keep], v[keep]


def cases_for(rng, material):
    parts = [random_cases(rng, CASES // 3), lobe_cases(rng, CASES // 3)]
    if material.iridescence == "grating":
        parts.append(order_cases(rng, material, CASES // 3))
    parts.append(stack(DEGENERATE.values()))
    return tuple(np.concatenate(arrays) for arrays in zip(*parts, strict=True))


def mirror_scale(material, cases) -> float:
    """The brightest the same lobe reflects with reflectance 1 (the paper's A-S without
    rotation or Fresnel): a film of index 1 on air reflects exactly 0, and its fp32
    rounding (~1e-8 of this) is measured against what the lobe could reflect."""
    mirror = Material(mdf="ashikhmin", ex=material.ex, ey=material.ey, theta1=0.0, theta2=0.0,
                      ks=material.ks)
    return float(np.abs(ref.reflected_radiance(mirror, *cases)).max())


def check(renderer, material, cases, wavelengths):
    n, t, l, v = cases
    gl = renderer.probe(material, n, t, l, v, wavelengths)
    expected = ref.reflected_radiance(material, n, t, l, v, wavelengths)
    scale = max(float(np.abs(expected).max()), mirror_scale(material, cases))
    check_probe(gl, expected, scale=scale)
    return float(probe_error(gl, expected, scale).max()), gl


@pytest.mark.parametrize("source", ["thin-film", "grating"])
def test_200_random_parameter_sets_agree(renderer, source):
    rng = np.random.default_rng(14 if source == "thin-film" else 15)
    make = film_material if source == "thin-film" else grating_material
    worst = 0.0
    for _ in range(200):
        material = make(rng)
        wavelengths = int(rng.choice(WAVELENGTH_CHOICES))
        if source == "grating" and wavelengths > 32:
            wavelengths = 32  # (2M+1)·N Bessel series per case: keep the suite fast
        worst = max(worst, check(renderer, material, cases_for(rng, material), wavelengths)[0])
    print(f"{source}: 200 random sets, worst error {worst:.3g} of the bound")


FILM_ENDS = {
    "film_ior": (1.0, 3.0),
    "substrate_ior": (1.0, 4.0),
    "film_thickness_max": (0.0, 2000.0),
    "ex": (0.0, 1e6),
    "ey": (0.0, 1e6),
}
GRATING_ENDS = {
    "grating_pitch": (0.2, 20.0),
    "grating_orders": (1, 8),
    "grating_depth": (0.0, 400.0),
    "ex": (0.0, 1e6),
    "ey": (0.0, 1e6),
}


def grid(ends: dict) -> list[dict]:
    names = list(ends)
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*ends.values())]


@pytest.mark.parametrize("wavelengths", [0, 16])
@pytest.mark.parametrize("source", ["thin-film", "grating"])
def test_extremes_grid_agrees(renderer, source, wavelengths):
    """Every combination of the ends of every new range (32 materials per source),
    with grazing and degenerate geometry: finite, non-negative, within the bound."""
    rng = np.random.default_rng(4)
    ends = FILM_ENDS if source == "thin-film" else GRATING_ENDS
    for fields in grid(ends):
        material = Material(iridescence=source, **fields)
        check(renderer, material, cases_for(rng, material), wavelengths)


@pytest.mark.parametrize("wavelengths", [0, 32])
def test_total_internal_reflection_reflects_everything(renderer, wavelengths):
    """A substrate below the outer index (outside the request range, built unchecked):
    beyond the critical angle v·h the film reflects all light in the shader too."""
    material = Material.model_construct(
        **{**Material().model_dump(), "iridescence": "thin-film", "mdf": "ashikhmin",
           "ex": 10.0, "ey": 10.0, "substrate_ior": 0.8, "film_ior": 1.4,
           "film_thickness_max": 300.0}
    )
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    t = np.tile([1.0, 0.0, 0.0], (3, 1))
    # Mirror cases (h = n) with v·h = cos 60°, 45° and 80°: sin θ1 > 0.8 for the last two... and
    # 0.87 > 0.8 for the first.
    angles = np.radians([60.0, 70.0, 80.0])
    v = np.stack([np.sin(angles), 0 * angles, np.cos(angles)], axis=1)
    l = v * [-1.0, 1.0, 1.0]
    gl = check(renderer, material, (n, t, l, v), wavelengths)[1]
    d = ref.mdf_ashikhmin(0.0, 0.0, 1.0, 10.0, 10.0)
    full = d / (4.0 * np.cos(angles) * np.cos(angles)) * np.cos(angles)  # R = 1, ks = 1
    assert np.allclose(gl, full[:, None], rtol=1e-4)


@pytest.mark.parametrize("wavelengths", [0, 64])
def test_shader_orders_land_where_the_grating_equation_puts_them(renderer, wavelengths):
    """Views where the first order's λ = d·(l + v)·b is 450, 530 and 630 nm come out blue,
    green and red in the shader, fast path and spectral alike: going away from the
    specular, violet first."""
    material = Material(iridescence="grating", ex=3e4, ey=3e4, grating_pitch=1.6,
                        grating_orders=1)
    targets = np.array([450.0, 530.0, 630.0])
    s = targets / 1600.0
    lb, vb = 0.5 * s - 0.3, 0.5 * s + 0.3
    zeros = np.zeros_like(s)
    l = np.stack([zeros, lb, np.sqrt(1 - lb * lb)], axis=1)
    v = np.stack([zeros, vb, np.sqrt(1 - vb * vb)], axis=1)
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    t = np.tile([1.0, 0.0, 0.0], (3, 1))
    gl = renderer.probe(material, n, t, l, v, wavelengths)
    assert list(gl.argmax(axis=1)) == [2, 1, 0], gl


METALS = ("gold", "silver", "copper", "aluminium", "titanium", "iron", "bismuth", "artist")


def conductor_material(rng: np.random.Generator) -> Material:
    """A film on a random metal (issue 23): a tabulated one or an artist's F0 and tint."""
    return film_material(
        rng, substrate="conductor", metal=str(rng.choice(METALS)),
        metal_f0=tuple(float(x) for x in rng.uniform(0.0, 1.0, 3)),
        metal_edge_tint=tuple(float(x) for x in rng.uniform(0.0, 1.0, 3)))


def test_100_random_conductor_sets_agree(renderer):
    rng = np.random.default_rng(23)
    worst = 0.0
    for _ in range(100):
        material = conductor_material(rng)
        wavelengths = int(rng.choice(WAVELENGTH_CHOICES))
        worst = max(worst, check(renderer, material, cases_for(rng, material), wavelengths)[0])
    print(f"conductor: 100 random sets, worst error {worst:.3g} of the bound")


# The artist's F0 (1 is taken as 0.99, metals.F0_MAX) with tints 0 and 1 gives n ≈ 400
# (k = 0) and n ≈ 0.005, k ≈ 1; tint 0.5 about n ≈ 200, k ≈ 100: the metals' extremes,
# far beyond the tables' k ≤ 8.5.
CONDUCTOR_ENDS = {
    "film_ior": (1.0, 3.0),
    "film_thickness_max": (0.0, 2000.0),
    "metal_f0": ((0.0, 0.0, 0.0), (1.0, 0.5, 1.0)),
    "metal_edge_tint": ((0.0, 0.5, 1.0), (1.0, 1.0, 0.0)),
    "ex": (0.0, 1e6),
}


@pytest.mark.parametrize("wavelengths", [0, 16])
def test_conductor_extremes_grid_agrees(renderer, wavelengths):
    rng = np.random.default_rng(8)
    for fields in grid(CONDUCTOR_ENDS):
        material = Material(iridescence="thin-film", substrate="conductor", metal="artist",
                            ey=1e3, **fields)
        check(renderer, material, cases_for(rng, material), wavelengths)
