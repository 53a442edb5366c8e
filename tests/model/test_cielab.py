"""The package's own CIELAB (model/cielab.py) against colour-science, which bench/ uses."""

from __future__ import annotations

import colour
import numpy as np

from opaline.model.cielab import chroma, srgb_to_lab


def colour_lab(rgb: np.ndarray) -> np.ndarray:
    with colour.utilities.suppress_warnings(colour_usage_warnings=True):
        white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
        return colour.XYZ_to_Lab(colour.sRGB_to_XYZ(rgb), white)


def test_lab_matches_colour_science_over_the_cube_and_near_black():
    rng = np.random.default_rng(7)
    rgb = np.concatenate([rng.random((2000, 3)), rng.random((200, 3)) * 0.03,
                          np.eye(3), np.zeros((1, 3)), np.ones((1, 3))])
    assert np.abs(srgb_to_lab(rgb) - colour_lab(rgb)).max() < 1e-9


def test_greys_have_no_chroma_and_red_its_known_chroma():
    # The 4-digit matrix leaves white 0.01 off the grey axis: far below a visible hue.
    greys = np.linspace(0.0, 1.0, 11)[:, None].repeat(3, axis=1)
    assert chroma(srgb_to_lab(greys)).max() < 0.01
    assert np.allclose(srgb_to_lab(np.ones(3)), [100.0, 0.0, 0.0], atol=0.01)
    # sRGB red: L* 53.23, a* 80.11, b* 67.22 (C*ab 104.58).
    assert np.allclose(srgb_to_lab([1.0, 0.0, 0.0]), [53.23, 80.11, 67.22], atol=0.01)
    assert np.isclose(chroma(srgb_to_lab([1.0, 0.0, 0.0])), 104.58, atol=0.01)
