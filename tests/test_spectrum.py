"""Continuous spectrum (opaline.model.spectrum): anchors, bins and white-balanced weights."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.spectrum import ANCHORS_NM, rgb_weights, rotation_at, sample_wavelengths


def test_rotation_passes_through_the_anchors_and_extends_linearly():
    """θ(612) = 0, θ(549) = θ1, θ(465) = θ2, and the end segments continue straight."""
    theta = rotation_at(np.array(ANCHORS_NM), 0.3, 0.7)
    np.testing.assert_allclose(theta, [0.0, 0.3, 0.7], atol=1e-15)
    beyond = rotation_at(np.array([380.0, 400.0, 700.0, 780.0]), 0.3, 0.7)
    assert np.diff(beyond[:2]) == pytest.approx((0.7 - 0.3) / (465 - 549) * 20)
    assert np.diff(beyond[2:]) == pytest.approx((0.0 - 0.3) / (612 - 549) * 80)


def test_wavelengths_are_bin_midpoints_over_the_visible_range():
    """N bins of equal width over 380 … 780 nm, sampled at their centres."""
    np.testing.assert_allclose(sample_wavelengths(4), [430.0, 530.0, 630.0, 730.0])


@pytest.mark.parametrize("count", [3, 16, 128])
def test_weights_are_white_balanced_and_shared_read_only(count):
    """Equal D at every wavelength gives R = G = B = D; the cached array cannot be changed."""
    weights = rgb_weights(count)
    assert weights.shape == (count, 3)
    np.testing.assert_allclose(weights.sum(axis=0), 1.0, atol=1e-12)
    assert rgb_weights(count) is weights
    with pytest.raises(ValueError):
        weights[0, 0] = 1.0
