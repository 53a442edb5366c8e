"""Output colour spaces (model/color_space.py) against colour-science, and the gamut map's
promises: luminance and the hue line kept, nothing below 0, a colour inside untouched."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from opaline.model import color_space
from opaline.model.display import display_encode, neutral

colour = pytest.importorskip("colour")

NAMES = {"srgb": "sRGB", "display-p3": "Display P3", "rec2020": "ITU-R BT.2020"}


@pytest.mark.parametrize("space", color_space.COLOR_SPACES)
def test_primaries_match_colour_science(space):
    """RGB → XYZ from the xy primaries and D65, as colour-science's colourspace has it."""
    theirs = colour.RGB_COLOURSPACES[NAMES[space]].matrix_RGB_to_XYZ
    np.testing.assert_allclose(color_space.rgb_to_xyz(space), theirs, atol=2e-4)


@pytest.mark.parametrize("space", color_space.COLOR_SPACES)
def test_transfer_curves_match_colour_science(space):
    x = np.linspace(0.0, 1.0, 1001)
    if space == "rec2020":  # BT.2020's curve with its exact constants (the ICC profile's)
        from colour.models.rgb.transfer_functions.itur_bt_2020 import CONSTANTS_BT2020_PRECISE

        theirs = colour.models.oetf_BT2020(x, constants=CONSTANTS_BT2020_PRECISE)
    else:
        theirs = colour.models.eotf_inverse_sRGB(x)
    np.testing.assert_allclose(color_space.encode(x, space), theirs, atol=1e-9)
    np.testing.assert_allclose(color_space.decode(color_space.encode(x, space), space), x,
                               atol=1e-9)


def test_a_wider_space_holds_an_srgb_cyan_beyond_it():
    """sRGB's green-blue edge lies inside Display P3 and Rec. 2020: no channel below 0."""
    cyan = np.array([0.0, 0.6, 0.7])
    for space in ("display-p3", "rec2020"):
        assert (cyan @ color_space.from_srgb(space).T).min() > 0.0


colours = st.tuples(*[st.floats(-0.5, 2.0)] * 3).map(np.array)


@settings(max_examples=300, deadline=None)
@given(colours, st.sampled_from(color_space.COLOR_SPACES))
def test_gamut_map_keeps_luminance_and_the_hue_line(x, space):
    """A colour with a channel below 0 moves toward the grey of its luminance, to where the
    lowest channel is 0: same luminance, on the line from that grey through the colour."""
    assume(np.abs(x).max() > 1e-9)  # radiance, not denormals whose products underflow
    mapped = color_space.gamut_map(x, space)
    y = float(x @ color_space.luminance(space))
    assert mapped.min() >= 0.0
    if y <= 0.0:
        assert np.all(mapped == 0.0)
    elif x.min() >= 0.0:
        np.testing.assert_array_equal(mapped, x)
    else:
        assert float(mapped @ color_space.luminance(space)) == pytest.approx(y, rel=1e-9)
        assert mapped.min() == pytest.approx(0.0, abs=1e-12)
        away, toward = x - y, mapped - y  # both from the grey: one direction, shorter
        assert np.allclose(np.cross(away, toward), 0.0, atol=1e-9 * (1.0 + abs(away).max()))
        assert float(away @ toward) > 0.0


def test_the_map_keeps_hue_where_the_clip_moved_it():
    """A free film's cyan (linear sRGB with red below 0, from tests/model/test_gamut.py's
    case): mapped, its CIELAB hue moves 2.4°, clipped 4.3° (hue is not constant along a
    line to white in linear RGB, so the map keeps it better, not exactly)."""
    exact = np.array([-0.02083648, 0.04612198, 0.05027359])

    def hue(rgb):
        lab = colour.XYZ_to_Lab(colour.RGB_to_XYZ(rgb, colour.RGB_COLOURSPACES["sRGB"],
                                                  apply_cctf_decoding=False))
        return np.degrees(np.arctan2(lab[2], lab[1]))

    mapped = abs(hue(color_space.gamut_map(exact, "srgb")) - hue(exact))
    clipped = abs(hue(np.maximum(exact, 0.0)) - hue(exact))
    assert mapped < 3.0 and mapped < 0.6 * clipped


@pytest.mark.parametrize("space", color_space.COLOR_SPACES)
def test_display_encoding_of_an_srgb_grey_is_the_same_grey_everywhere(space):
    """A grey (and the preset backgrounds' greys) shows as the same grey in every space: the
    spaces share D65 and (but Rec. 2020) the curve."""
    grey = np.full(3, 0.18)
    shown = display_encode(grey, "none", space)
    np.testing.assert_allclose(shown, shown[0], atol=1e-9)
    np.testing.assert_allclose(color_space.decode(shown, space), 0.18, atol=1e-9)
    background = color_space.display_background([0.12, 0.12, 0.13], space)
    np.testing.assert_allclose(color_space.decode(background, space) @ color_space.luminance(space),
                               color_space.decode([0.12, 0.12, 0.13], "srgb")
                               @ color_space.luminance("srgb"), rtol=1e-9)


def test_display_encoding_in_srgb_is_the_tone_map_and_curve_inside_the_gamut():
    x = np.random.default_rng(3).uniform(0.0, 3.0, (100, 3))
    np.testing.assert_allclose(display_encode(x, "neutral"),
                               color_space.encode(neutral(x), "srgb"), atol=1e-12)
