"""The GLSL shading agrees with the float64 NumPy reference, function by function."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.model import reference as ref
from opaline.model.params import Material, RenderRequest
from stability_cases import random_cases

pytestmark = pytest.mark.gl

PLOT_TOLERANCE = 1e-4  # max abs error relative to the plot's peak (issue 2)
FIGURE_MATERIALS = [
    Material(mdf="ashikhmin", ex=100, ey=10, theta1=0.2, theta2=0.4),  # Figs. 2, 3
    Material(mdf="ashikhmin", ex=10, ey=100, theta1=0.2, theta2=0.4),
    Material(mu_f=5, alpha=1, beta=1),  # Fig. 6
    Material(mu_f=10, alpha=1, beta=0.1),  # Fig. 7
    Material(mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1, theta2=0.2),  # Fig. 9 left
    Material(mu_f=2.5, alpha=1.0, beta=5.0, theta1=0.1, theta2=0.2),  # Fig. 9 right
    Material(mu_f=2, alpha=1, beta=0.1, theta1=0.3, theta2=0.6),  # Fig. 10
    Material(mu_f=10, alpha=20, beta=1, theta1=0.1, theta2=0.2),  # Fig. 14 top
    Material(mu_f=3, alpha=2, beta=1, theta1=math.pi / 6, theta2=math.pi / 3),  # Fig. 14 bottom
]


def random_material(rng: np.random.Generator) -> Material:
    """A material drawn across the full ranges of docs/design.md §5 (exponents log-uniform)."""
    return Material(
        mdf=str(rng.choice(["ashikhmin", "multipeak"])),
        ex=float(10 ** rng.uniform(-3, 6)),
        ey=float(10 ** rng.uniform(-3, 6)),
        mu_f=float(rng.uniform(0, 1000)),
        alpha=float(rng.uniform(0, 1000)),
        beta=float(rng.uniform(0, 1000)),
        theta1=float(rng.uniform(-2 * math.pi, 2 * math.pi)),
        theta2=float(rng.uniform(-2 * math.pi, 2 * math.pi)),
    )


def plot_error(renderer, material: Material, size: int, wavelengths: int = 0) -> float:
    gl = renderer.mdf_plot(material, size, wavelengths)
    expected = ref.mdf_plot(material, size, wavelengths)
    return float(np.abs(gl - expected).max() / max(expected.max(), 1e-30))


def test_mdf_plot_matches_reference_for_200_random_materials(renderer):
    """200 random parameter sets over the full ranges agree within 1e-4 of the peak."""
    rng = np.random.default_rng(2014)
    errors = [plot_error(renderer, random_material(rng), 96) for _ in range(200)]
    worst = max(errors)
    print(f"MDF plot, 200 random sets: worst error {worst:.3g} of peak")
    assert worst <= PLOT_TOLERANCE


@pytest.mark.parametrize("material", FIGURE_MATERIALS, ids=lambda m: f"{m.mdf}-{m.mu_f}-{m.ex}")
def test_mdf_plot_matches_reference_for_figure_parameters(renderer, material):
    """The paper's figure parameters agree at full plot resolution."""
    assert plot_error(renderer, material, 256) <= PLOT_TOLERANCE


@pytest.mark.parametrize("wavelengths", [3, 16, 64])
def test_spectral_mdf_plot_matches_reference(renderer, wavelengths):
    """The continuous-spectrum variant integrates the same wavelengths and weights."""
    material = Material(mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1, theta2=0.2)
    assert plot_error(renderer, material, 96, wavelengths) <= PLOT_TOLERANCE


def test_mdf_plot_layout_is_the_paper_convention(renderer):
    """+hx is right and +hy up: an A-S lobe with ex < ey is wide along x (row 0 at top)."""
    plot = renderer.mdf_plot(Material(mdf="ashikhmin", ex=10, ey=1000, theta1=0, theta2=0), 64)
    row = plot[32, :, 0]
    col = plot[:, 32, 0]
    assert (row > 0.5 * row.max()).sum() > 2 * (col > 0.5 * col.max()).sum()
    rotated = renderer.mdf_plot(Material(mdf="ashikhmin", ex=10, ey=1000, theta1=0.5, theta2=0), 64)
    # Eq. 2 turns the half vector counter-clockwise, D_g(h) = D(R_θ h), so the
    # plotted lobe turns clockwise: its x-wide band tilts into the upper left.
    upper_right = rotated[:32, 32:, 1].sum()
    upper_left = rotated[:32, :32, 1].sum()
    assert upper_left > 1.5 * upper_right


def shading_cases(rng, count):
    """Random frames with l and v in the upper hemisphere of n, plus degenerate cases."""
    n, t, l, v = random_cases(rng, count)
    # Degenerate geometry (docs/design.md §8): l = -v, h exactly along n, t parallel to n, grazing.
    n[:4] = [0.0, 0.0, 1.0]
    t[:4] = [[1, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 0]]
    l[:4] = [[0, 0, 1], [0, 0, 1], [1, 0, 0], [0.6, 0, 0.8]]
    v[:4] = [[0, 0, 1], [0, 0, 1], [-1, 0, 0], [-0.6, 0, 0.8]]
    return n, t, l, v


@pytest.mark.parametrize("seed", range(6))
def test_shading_matches_reference(renderer, seed):
    """Reflected radiance per (n, t, l, v) case agrees with float64 within fp32 accuracy."""
    rng = np.random.default_rng(seed)
    material = Material(
        mdf="ashikhmin" if seed % 2 else "multipeak",
        ex=float(10 ** rng.uniform(0, 3)),
        ey=float(10 ** rng.uniform(0, 3)),
        mu_f=float(rng.uniform(0, 20)),
        alpha=float(rng.uniform(0, 5)),
        beta=float(rng.uniform(0, 5)),
        theta1=float(rng.uniform(-1, 1)),
        theta2=float(rng.uniform(-1, 1)),
        kd=float(rng.uniform(0, 1)),
        ks=float(rng.uniform(0, 2)),
        albedo=tuple(rng.uniform(0, 1, 3)),
        f0=float(rng.choice([1.0, rng.uniform(0, 1)])),
    )
    n, t, l, v = shading_cases(rng, 1000)
    gl = renderer.probe(material, n, t, l, v)
    expected = ref.reflected_radiance(material, n, t, l, v)
    assert np.all(np.isfinite(gl))
    scale = max(float(np.abs(expected).max()), 1e-6)
    err = np.abs(gl - expected) / (np.abs(expected) + 1e-3 * scale)
    assert float(err.max()) < 2e-3, f"worst case {int(err.max(axis=1).argmax())}"


def test_no_specular_when_light_is_opposite_view(renderer):
    """l = -v has no half vector: only the diffuse term remains, finite."""
    material = Material(kd=0.5, ks=10.0, albedo=(1.0, 0.5, 0.25))
    n = np.array([[0.0, 0.0, 1.0]])
    gl = renderer.probe(material, n, np.array([[1.0, 0.0, 0.0]]), n, -n)
    expected = 0.5 * np.array([1.0, 0.5, 0.25]) / np.pi
    assert np.allclose(gl[0], expected, rtol=1e-5)


@pytest.mark.parametrize(("tonemap", "space"), [
    ("none", "srgb"), ("reinhard", "srgb"), ("aces", "srgb"), ("neutral", "srgb"),
    ("neutral", "display-p3"), ("none", "rec2020")])
def test_display_encoding_matches_reference(renderer, tonemap, space):
    """The resolve's exposure, output primaries, gamut map, tone map and transfer curve agree
    with the float64 twin (model/display.py) on the renderer's own linear radiance, over
    pixels below and above neutral's knee and pixels outside sRGB (the oil slick's
    spectral bands)."""
    from dataclasses import replace

    from opaline.model.display import KS, display_encode
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve

    exposure = 20.0  # oil-slick's radiance spans neutral's knee at KS = 0.76 at this exposure
    job = resolve(RenderRequest(preset="oil-slick", width=64, height=64, quality="draft",
                                transparent=True, tonemap=tonemap, exposure=exposure,
                                format="npy"), get_preset("oil-slick"))
    linear = renderer.render(job).linear.astype(np.float64)
    display = renderer.render(replace(job, format="png16", color_space=space)).display
    coverage = linear[..., 3]
    covered = coverage > 0.0
    straight = linear[covered, :3] / coverage[covered, None] * exposure
    peaks = straight.max(axis=1)
    assert (peaks < KS).sum() > 50 and (peaks > 2.0).sum() > 50  # both branches exercised
    assert (straight.min(axis=1) < -1e-3).sum() > 20  # and the gamut map
    expected = display_encode(straight, tonemap, space)
    assert np.abs(display[covered, :3] - expected).max() < 1e-4
    assert np.allclose(display[..., 3], np.clip(coverage, 0.0, 1.0), atol=1e-6)


@pytest.mark.parametrize("space", ["srgb", "display-p3", "rec2020"])
@pytest.mark.parametrize("fmt", ["png", "png16"])
def test_the_background_is_the_same_colour_in_every_space(renderer, space, fmt):
    """The preset's background (display sRGB) is drawn as the same colour's display values
    in the output's space, by the one-sample direct draw (png, draft) and the resolve."""
    from opaline.model import color_space
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve

    preset = get_preset("bragg-mirror")
    job = resolve(RenderRequest(preset="bragg-mirror", width=32, height=32, quality="draft",
                                samples=1, format=fmt, color_space=space, environment="none"),
                  preset)
    frame = renderer.render(job, preset)
    corner = (frame.pixels[0, 0, :3] / 255.0 if fmt == "png" else frame.display[0, 0, :3])
    want = color_space.display_background(preset.background, space)
    np.testing.assert_allclose(corner, want, atol=0.6 / 255.0 if fmt == "png" else 1e-4)
