"""A grating's orders under an environment (model/grating_environment.py), held to what it
approximates: each order's albedo to a quadrature of the grating's own reflectance
(model/grating.py), and the reads along the orders' curve to the spectral integral of
every order, wavelength by wavelength."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opaline.model import grating, visible
from opaline.model import grating_environment as ge
from opaline.model.microfacet import fresnel_schlick
from opaline.model.params import Material

FRAME = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]))


def cd(ex: float = 3000.0, ey: float = 30000.0, **fields) -> Material:
    values = dict(iridescence="grating", mdf="ashikhmin", ex=ex, ey=ey, grating_pitch=1.6,
                  grating_orders=3, grating_depth=150.0, f0=0.9, ks=1.0, kd=0.0)
    return Material(**{**values, **fields})


def unit(x: float, y: float) -> np.ndarray:
    return np.array([x, y, math.sqrt(1.0 - x * x - y * y)])


@pytest.mark.parametrize("ex,ey", [(3000.0, 30000.0), (1000.0, 1000.0), (300.0, 300.0)])
@pytest.mark.parametrize("m,lam", [(0, 550.0), (1, 450.0), (-2, 600.0), (3, 420.0)])
def test_an_orders_albedo_is_its_lobe_integrated(ex, ey, m, lam):
    """∫ η_m·lobe_m·(n·l) dω_l about the order's light is η_m·F(n·v)·(n·v)/max(n·l, n·v)
    within 3 % (a lobe narrower than its curvature: the exponents the presets use and
    down to 300)."""
    material = cd(ex, ey)
    v = unit(0.2, 0.35 if m >= 0 else -0.35)
    shift = m * lam / 1600.0
    light = ge.order_light_at(v, shift)
    assert light[2] > 0.0
    width = 8.0 * math.sqrt(ge.footprint(ge.lobe_solid_angle(material), light[2], v[2], 0.0))
    axis = np.linspace(-width, width, 801)
    lt, lb = np.meshgrid(light[0] + axis, light[1] + axis, indexing="ij")
    lz = np.sqrt(np.maximum(1.0 - lt * lt - lb * lb, 0.0))
    l = np.stack([lt, lb, lz], -1)
    term = grating.order_term(material, FRAME, l, np.broadcast_to(v, l.shape), m, lam)
    integral = float(np.sum(term * lz / np.maximum(lz, 1e-12)) * (axis[1] - axis[0]) ** 2)
    eta = float(grating.efficiency(m, lam, 150.0, light[2] + v[2]))
    albedo = eta * float(fresnel_schlick(0.9, v[2])) * v[2] / max(light[2], v[2])
    assert integral == pytest.approx(albedo, rel=0.03 if ex >= 1000.0 else 0.06)


def spectral_sum(material: Material, v: np.ndarray) -> np.ndarray:
    """Every order at every nm under a constant map of radiance 1: the integral the reads
    approximate, wavelength by wavelength."""
    lam = np.arange(380.0, 780.5, 0.25)
    density = visible.density_at(lam)
    total = np.zeros(3)
    for m in range(1, material.grating_orders + 1):
        for sign in (-1, 1):
            light = ge.order_light_at(v, sign * m * lam / 1600.0)
            lz = light[..., 2]  # 0 where the order is evanescent
            eta = grating.efficiency(m, lam, 150.0, lz + v[2])
            per_nm = np.where((lz > 0.0)[..., None],
                              density * (eta / np.maximum(lz, v[2]))[..., None], 0.0)
            total += np.trapezoid(per_nm, lam, axis=0)
    eta0 = np.array([float(grating.efficiency(0, c, 150.0, 2.0 * v[2]))
                     for c in grating.channel_wavelengths()])
    return float(fresnel_schlick(0.9, v[2])) * v[2] * (total + eta0 / v[2])


@pytest.mark.parametrize("vx,vy", [(0.0, 0.0), (0.2, -0.35), (-0.5, 0.6), (0.05, 0.95),
                                   (0.9, 0.1)])
def test_the_curves_reads_sum_every_order_at_every_wavelength(vx, vy):
    """Under a constant map, the reads' weights are the spectral integral of every order:
    the pieces cover the curve once, nothing twice, whatever the offset they are cut at
    (a pixel's and pass's own): to 0.1 % with many reads of a lobe too sharp to blur the
    spectrum (ey 1e6) and 0.5 % with the preset's (its lobe blurs where an order meets
    the horizon); at the tiers' 2-3 pieces a pass, whose pieces take η at two points each,
    within 20 % at any offset and 8 % over a pixel's offsets on average."""
    def constant(l, solid_angle):
        return np.ones(np.shape(l))
    v = unit(vx, vy)
    offsets = np.linspace(0.0, 1.0, 16, endpoint=False)
    for ey, reads in ((1e6, 4096), (30000.0, 4096)):
        material = cd(ey=ey)
        expected = spectral_sum(material, v)
        for offset in offsets[::5]:
            got = ge.environment_grating(material, v, constant, reads, offset)
            np.testing.assert_allclose(got, expected, rtol=1e-3 if ey > 1e5 else 5e-3,
                                       atol=1e-4 * expected.max())
    material = cd()
    expected = spectral_sum(material, v)
    for reads in (2, 3):
        got = np.stack([ge.environment_grating(material, v, constant, reads, o)
                        for o in offsets])
        error = np.abs(got / expected - 1.0)
        assert float(error.max()) <= 0.2 and float(error.mean()) <= 0.08, (reads, error.max())


def test_each_read_lights_the_orders_that_leave_through_it():
    """A map bright on one stretch of the curve only: what comes back is the order whose
    wavelengths leave through it (for a CD seen head-on, b in 0.30-0.45 is the first order
    at 480-720 nm: it is lit, and the second order, which leaves through 0.475 and on, is
    not), and nothing comes back from the other side of the mirror direction."""
    material = cd(ey=1e6, grating_orders=2)  # a lobe too sharp to blur the band's edges
    v = unit(0.0, 0.0)

    def band(l, solid_angle):
        return np.where(((l[..., 1] > 0.30) & (l[..., 1] < 0.45))[..., None], 1.0, 0.0) + 0.0 * l

    offsets = np.linspace(0.0, 1.0, 4, endpoint=False)
    one_side = np.mean([ge.environment_grating(material, v, band, 1024, o)
                        for o in offsets], axis=0)
    first_only = np.mean([ge.environment_grating(cd(ey=1e6, grating_orders=1), v, band, 1024, o)
                          for o in offsets], axis=0)
    # The second order adds nothing (its pieces fall elsewhere: only where the band's
    # edges cut a piece do the two materials' cuts, which differ, tell them apart).
    np.testing.assert_allclose(one_side, first_only, rtol=0.02, atol=0.002)
    lam = np.arange(480.0, 720.5, 0.25)
    eta = grating.efficiency(1, lam, 150.0, np.sqrt(1.0 - (lam / 1600.0) ** 2) + 1.0)
    expected = float(fresnel_schlick(0.9, 1.0)) * np.trapezoid(
        visible.density_at(lam) * eta[:, None], lam, axis=0)
    np.testing.assert_allclose(one_side, np.maximum(expected, 0.0), rtol=0.02, atol=0.002)
