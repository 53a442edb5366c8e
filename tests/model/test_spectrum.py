"""Continuous spectrum (opaline.model.spectrum): anchors, bins and white-balanced weights."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.spectrum import (
    ANCHORS_NM,
    rgb_weights,
    rotation_at,
    sample_wavelengths,
    wavelength_shift,
)


def test_rotation_passes_through_the_anchors_and_holds_beyond_them():
    """θ(612) = 0, θ(549) = θ1, θ(465) = θ2, linear between; θ2 below 465 nm and 0 above
    612 nm, so at θ = ±2π the spectrum spans no more rotation than the user asked for."""
    theta = rotation_at(np.array(ANCHORS_NM), 0.3, 0.7)
    np.testing.assert_allclose(theta, [0.0, 0.3, 0.7], atol=1e-15)
    assert rotation_at(np.array([507.0]), 0.3, 0.7)[0] == pytest.approx(0.5)
    beyond = rotation_at(np.array([380.0, 400.0, 700.0, 780.0]), 0.3, 0.7)
    np.testing.assert_allclose(beyond, [0.7, 0.7, 0.0, 0.0])
    extreme = rotation_at(np.linspace(380.0, 780.0, 401), -2 * np.pi, 2 * np.pi)
    assert extreme.min() == pytest.approx(-2 * np.pi) and extreme.max() == pytest.approx(2 * np.pi)


def test_wavelengths_are_bin_midpoints_over_the_visible_range():
    """N bins of equal width over 380 … 780 nm, sampled at their centres."""
    np.testing.assert_allclose(sample_wavelengths(4), [430.0, 530.0, 630.0, 730.0])
    np.testing.assert_allclose(sample_wavelengths(4, 0.0), [380.0, 480.0, 580.0, 680.0])


def test_supersamples_spread_their_wavelengths_over_the_bins():
    """One sample takes the midpoints; N samples take N distinct shifts that cover [0, 1)
    with no gap wider than 2/N (golden-ratio sequence), so N·W points integrate the spectrum."""
    assert wavelength_shift(0, 1) == 0.5
    for n in (2, 4, 16, 64):
        shifts = np.sort([wavelength_shift(i, n) for i in range(n)])
        assert len(np.unique(shifts)) == n
        gaps = np.diff(np.concatenate([shifts, [shifts[0] + 1.0]]))
        assert gaps.max() <= 2.0 / n + 1e-12


@pytest.mark.parametrize("count", [3, 16, 128])
def test_weights_are_white_balanced_and_shared_read_only(count):
    """Equal D at every wavelength gives R = G = B = D; the cached array cannot be changed."""
    weights = rgb_weights(count)
    assert weights.shape == (count, 3)
    np.testing.assert_allclose(weights.sum(axis=0), 1.0, atol=1e-12)
    assert rgb_weights(count) is weights
    with pytest.raises(ValueError):
        weights[0, 0] = 1.0


def test_shipped_cmfs_are_colour_sciences():
    """The CIE 1931 table and D65 shipped with the package give colour-science's values
    (to 1e-5; D65 at its own 5 nm steps exactly, between them linearly as CIE recommends;
    the weights, CMFs under D65, to 2e-6) at any wavelength. Regenerate the files with:
    np.save(path, column_stack([lam, MSDS_CMFS[...][lam]])) for lam = 360 … 830 by 0.1 nm;
    np.save(path, column_stack([lam, SDS_ILLUMINANTS["D65"][lam]])) for lam = 300 … 780 by 5."""
    import colour
    import numpy as np

    from opaline.model import spectrum

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    lam = np.random.default_rng(7).uniform(380.0, 780.0, 500)
    assert np.abs(spectrum.cie_xyz(lam) - np.asarray(cmfs[lam])).max() < 1e-5
    assert np.allclose(spectrum.XYZ_TO_SRGB, colour.models.RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB)
    d65 = colour.SDS_ILLUMINANTS["D65"]
    steps = np.arange(300.0, 781.0, 5.0)
    assert np.array_equal(spectrum.illuminant_d65(steps), np.asarray(d65[steps]))
    for count, shift in ((4, 0.5), (16, 0.123), (128, 0.9)):
        lam = spectrum.sample_wavelengths(count, shift)
        d65_linear = colour.SpectralDistribution(d65).interpolate(
            colour.SpectralShape(300.0, 780.0, 0.1), interpolator=colour.LinearInterpolator)
        lit = np.asarray(cmfs[lam]) * np.asarray(d65_linear[lam])[:, None]
        rgb = lit @ spectrum.XYZ_TO_SRGB.T
        expected = rgb / rgb.sum(axis=0, keepdims=True)
        assert np.abs(spectrum.rgb_weights(count, shift) - expected).max() < 2e-6


def test_spectral_weights_do_not_import_colour_science():
    """A spectral render's weights come from the shipped table: no colour-science (and its
    scipy and matplotlib imports, over a second cold) in the rendering process."""
    import subprocess
    import sys

    code = ("import sys; from opaline.model.spectrum import rgb_weights; rgb_weights(8); "
            "from opaline.model.visible import density_table; density_table(); "
            "assert 'colour' not in sys.modules and 'scipy' not in sys.modules, "
            "sorted(m for m in sys.modules if m.startswith(('colour', 'scipy')))[:5]")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
