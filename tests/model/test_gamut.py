"""What Opaline does with a colour outside sRGB (docs/physics.md §1.4, "Gamut"): each linear sRGB
channel of a spectral sum that comes out below 0 is set to 0, the others kept, on the
spectral path and on the fast path alike.

The exact colour is colour-science's: ``thin_film_tmm`` at every nm under D65, to XYZ
and linear sRGB. A free soap film 460 nm thick seen face-on is a dim cyan that sRGB
cannot hold (its red channel is below 0); those tests fail if the shader's twin stops
clipping, maps the gamut another way or lets the negative channel through.
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


def test_the_spectral_path_clips_each_negative_channel_and_keeps_the_others():
    thickness, angle, exact = out_of_gamut_case()
    cos1 = np.cos(np.radians(angle))
    ours = thinfilm.film_rgb_spectral(cos1, thickness, *SOAP, 128)
    assert ours[0] == 0.0  # clipped, not mapped: the red channel alone goes to 0
    np.testing.assert_allclose(ours[1:], exact[1:], atol=2e-3)  # green and blue as exact


def test_the_fast_path_clips_the_same_colour():
    thickness, angle, exact = out_of_gamut_case()
    fast = thinfilm.film_rgb_fast(np.cos(np.radians(angle)), thickness, *SOAP)
    assert fast[0] == 0.0
    np.testing.assert_allclose(fast[1:], exact[1:], atol=0.01)
