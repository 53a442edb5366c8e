"""What Opaline does with a colour outside sRGB (docs/physics.md §1.4, "Gamut"): the
spectral sums and the fast path keep a channel below 0, and the display encoding moves
the colour toward the grey of its luminance (model/color_space.py), or shows it in a
wider space.

The exact colour is colour-science's: ``thin_film_tmm`` at every nm under D65, to XYZ
and linear sRGB. A free soap film 460 nm thick seen face-on is a dim cyan that sRGB
cannot hold (its red channel is below 0); those tests fail if the twin clips the channel
at the sum again.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from opaline.model import thinfilm

colour = pytest.importorskip("colour")

SOAP = (1.33, 1.0)  # a free film of water in air
NM = np.arange(360.0, 831.0, 1.0)


def exact_srgb(thickness_nm: float, angle_deg: float) -> np.ndarray:
    """Linear sRGB of the free film under D65, a white's Y = 1, by colour-science."""
    n = np.array([np.ones_like(NM), np.full_like(NM, SOAP[0]), np.full_like(NM, SOAP[1])])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r, _ = colour.phenomena.interference.thin_film_tmm(
            n, np.array([thickness_nm]), NM, np.array([angle_deg]))
    reflectance = r.mean(axis=-1).reshape(len(NM), 1)
    shape = colour.SpectralShape(360.0, 830.0, 1.0)
    xyz = colour.msds_to_XYZ(colour.MultiSpectralDistributions(reflectance, shape),
                             colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"],
                             colour.SDS_ILLUMINANTS["D65"], method="Integration",
                             shape=shape) / 100.0
    return np.asarray(colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"],
                                        apply_cctf_encoding=False)).reshape(3)


def out_of_gamut_case() -> tuple[float, float, np.ndarray]:
    """The first (thickness, angle) of a coarse scan whose exact red is well below 0."""
    for thickness in np.arange(200.0, 600.0, 20.0):
        for angle in (0.0, 30.0):
            rgb = exact_srgb(float(thickness), angle)
            if rgb[0] < -0.01 and rgb[1:].min() > 0.02:
                return float(thickness), angle, rgb
    raise AssertionError("no free-film colour out of sRGB on the scan")


def test_the_spectral_path_keeps_the_negative_channel_to_the_display():
    thickness, angle, exact = out_of_gamut_case()
    cos1 = np.cos(np.radians(angle))
    ours = thinfilm.film_rgb_spectral(cos1, thickness, *SOAP, 128)
    np.testing.assert_allclose(ours, exact, atol=2e-3)  # red below 0 included
    assert ours[0] < -0.01


def test_the_fast_path_keeps_it_too():
    thickness, angle, exact = out_of_gamut_case()
    fast = thinfilm.film_rgb_fast(np.cos(np.radians(angle)), thickness, *SOAP)
    np.testing.assert_allclose(fast, exact, atol=0.01)
    assert fast[0] < 0.0


def test_rec2020_shows_the_exact_colour():
    """The same cyan lies outside Display P3 too (its red there is -0.009) but inside
    Rec. 2020: encoded there it decodes to the exact colour."""
    from opaline.model import color_space
    from opaline.model.display import display_encode

    thickness, angle, exact = out_of_gamut_case()
    ours = thinfilm.film_rgb_spectral(np.cos(np.radians(angle)), thickness, *SOAP, 128)
    wide = exact @ color_space.from_srgb("rec2020").T
    assert wide.min() > 0.0 and (exact @ color_space.from_srgb("display-p3").T).min() < 0.0
    shown = color_space.decode(display_encode(ours, "none", "rec2020"), "rec2020")
    np.testing.assert_allclose(shown, wide, atol=3e-3)
