"""Float64 twin of ``glsl/lib/environment_grating.glsl``: a grating's orders read from an
environment map where they leave (docs/design.md §4.5).

Order m at wavelength λ is the Ashikhmin-Shirley lobe about the light l whose shifted
sum k_m = l + v − (mλ/d)·b lies along n (model/grating.py). In the frame (t, b, n) that
is l = (−v_t, b, √(r² − b²)), r = √(1 − v_t²), at b = ±mλ/d − v_b: every order at every
wavelength leaves along one curve, and at b it is order m's at λ = d·|b + v_b|/m. Over a
lobe narrower than the map's features an order reflects the map's radiance there times
its albedo

    ∫ η_m·F·D(h_m)·(v·h_m)/(|k_m|²·max(n·l, n·v))·(n·l) dω_l ≈ η_m(λ)·F(n·v)·(n·v)/max(n·l, n·v),

from dω_l = |k_m|²/(l·h_m)·dω_h and ∫ D dω_h ≈ 1 about h_m = n
(``tests/model/test_grating_environment.py`` checks it by quadrature). The two stretches
of the curve where some order can be seen, b + v_b ∈ ±[380/d, M·780/d] (widened by a
lobe's reach) within the horizon, are laid end to end and cut into ``reads`` pieces' length
from an offset, and once more where the first ends (``reads`` + 2 pieces, the first and
last shorter); each piece is read once and lights each order falling on it by the
spectrum's weight over the piece's wavelengths (``visible.cumulative_at``) times η_m at
two points of it; where the lobe is wider along b than the piece, by the lobe's box
scaled to the piece's share. The mirror order is one read at the mirror direction, its η
at each channel's centroid wavelength, as the fast path's lights (``grating.grating_fast``).
A read's radiance is filtered over the lobe's solid angle in l, |k|²/(n·l)·(1/D at its
peak), widened by the piece; the caller's ``radiance`` does the filtering.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from opaline.model import visible
from opaline.model.color_space import radiance_floor
from opaline.model.grating import channel_wavelengths, efficiency
from opaline.model.microfacet import EPS_DENOM, FloatArray, fresnel_schlick
from opaline.model.spectrum import RANGE_NM

if TYPE_CHECKING:
    from opaline.model.params import Material

# The map's radiance toward directions in the shading frame (..., 3), each read over a
# solid angle (...): (..., 3) linear RGB.
Radiance = Callable[[FloatArray, FloatArray], FloatArray]


def order_light_at(vl: FloatArray, shift: FloatArray | float) -> FloatArray:
    """Where an order leaves toward (shading frame) for a shift mλ/d along b: the light
    whose k = l + v − shift·b lies along n; (0, 0, 0) where it is evanescent."""
    vl = np.asarray(vl, dtype=np.float64)
    shift = np.asarray(shift, dtype=np.float64)
    lt = np.broadcast_to(-vl[..., 0], shift.shape)
    lb = shift - vl[..., 1]
    s = 1.0 - lt * lt - lb * lb
    inside = s > 0.0
    light: FloatArray = np.where(inside[..., None],
                                 np.stack([lt, lb, np.sqrt(np.where(inside, s, 0.0))], -1),
                                 0.0)
    return light


def lobe_solid_angle(material: Material) -> float:
    """1/D at the lobe's peak: the solid angle of half vectors it spans."""
    return 2.0 * math.pi / math.sqrt((material.ex + 1.0) * (material.ey + 1.0))


def footprint(lobe_h: float, lz: FloatArray, nv: FloatArray, stretch: FloatArray | float
              ) -> FloatArray:
    """The solid angle a read stands for: the lobe's in l, lobe_h·|k|²/(n·l), widened by
    a strip ``stretch`` long."""
    k = lz + nv
    lobe_l = lobe_h * k * k / np.maximum(lz, EPS_DENOM)
    result: FloatArray = lobe_l + stretch * np.sqrt(lobe_l)
    return result


def stretch_weight(material: Material, m: int, q: FloatArray, half: FloatArray,
                   kn: FloatArray) -> FloatArray:
    """Order m at the stretch |b + v_b| ∈ q ± half, (..., 3): over each half of its
    wavelengths, the spectrum's weight times η_m at that half's middle (η changes across
    a stretch: at one point a stretch the error under a constant map was about three
    times as large)."""
    per_nm = 1000.0 * material.grating_pitch / m
    lo, mid, hi = per_nm * (q - half), per_nm * q, per_nm * (q + half)
    visible_part = (hi > RANGE_NM[0]) & (lo < RANGE_NM[1])
    total = np.zeros(np.shape(q) + (3,))
    for a, b in ((lo, mid), (mid, hi)):
        # Held in the visible range, where the weights are (outside it a half weighs 0).
        lam = np.clip(0.5 * (a + b), *RANGE_NM)
        eta = efficiency(m, lam, material.grating_depth, kn)
        total = total + (visible.cumulative_at(b) - visible.cumulative_at(a)) * eta[..., None]
    result: FloatArray = np.where(visible_part[..., None], total, 0.0)
    return result


def widen(material: Material, kn: FloatArray | float) -> FloatArray:
    """The lobe's half-width along b in l, the box of its Gaussian's variance √3·|k|/√ey:
    a wavelength's light comes from that far either side of its order's direction."""
    result: FloatArray = math.sqrt(3.0) * np.asarray(kn, dtype=np.float64) / math.sqrt(
        material.ey + 1.0)
    return result


def curve_points(material: Material, vl: FloatArray, reads: int, offset: float
                 ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The reads' b (..., reads + 2), their pieces' lengths and their q = ±(b + v_b): the
    two stretches where an order is seen (and a lobe's reach about them) laid end to end,
    cut every step from ``offset`` steps before their start, and once more where the first
    ends, as the shader cuts them (a piece of length 0 reads nothing)."""
    pitch_nm = 1000.0 * material.grating_pitch
    r = np.sqrt(np.maximum(1.0 - vl[..., 0] ** 2, 0.0))[..., None]
    reach = widen(material, 1.0 + vl[..., 2])[..., None]
    q_lo = RANGE_NM[0] / pitch_nm - reach
    q_hi = material.grating_orders * RANGE_NM[1] / pitch_nm + reach
    vb = vl[..., 1][..., None]
    plus = np.clip(np.concatenate([q_lo - vb, q_hi - vb], -1), -r, r)
    minus = np.clip(np.concatenate([-q_hi - vb, -q_lo - vb], -1), -r, r)
    len_plus = (plus[..., 1] - plus[..., 0])[..., None]
    len_all = len_plus + (minus[..., 1:] - minus[..., :1])
    step = np.maximum(len_all, 1e-6) / reads
    join = np.floor(len_plus / step + offset) + 1.0

    def cut(i: FloatArray) -> FloatArray:
        k = np.where(i < join, i, i - 1.0) - offset
        result: FloatArray = np.where(i == join, len_plus, np.clip(k * step, 0.0, len_all))
        return result

    j = np.arange(reads + 2, dtype=np.float64)
    lo, hi = cut(j), cut(j + 1.0)
    on_plus = lo < len_plus
    middle = 0.5 * (lo + hi)
    b = np.where(on_plus, plus[..., :1] + middle, minus[..., :1] + middle - len_plus)
    q = np.where(on_plus, b + vb, -(b + vb))
    return b, hi - lo, q


def environment_grating(material: Material, vl: FloatArray, radiance: Radiance,
                        reads: int, offset: float = 0.0) -> FloatArray:
    """The specular radiance toward v (``vl`` (..., 3) in the shading frame) from every
    order, the curve cut into ``reads`` pieces' length at ``offset`` (see curve_points)."""
    vl = np.asarray(vl, dtype=np.float64)
    nv = vl[..., 2]
    safe_nv = np.maximum(nv, EPS_DENOM)
    lobe_h = lobe_solid_angle(material)
    eta0 = np.stack([efficiency(0, lam, material.grating_depth, np.maximum(2.0 * nv, 0.0))
                     for lam in channel_wavelengths()], axis=-1)
    mirror = np.stack([-vl[..., 0], -vl[..., 1], nv], axis=-1)
    total = eta0 / safe_nv[..., None] * radiance(mirror, footprint(lobe_h, nv, nv, 0.0))
    b, step, q = curve_points(material, vl, reads, offset)
    r2 = np.maximum(1.0 - vl[..., 0] ** 2, 0.0)[..., None]
    lz = np.sqrt(np.maximum(r2 - b * b, 0.0))
    lights = np.stack([np.broadcast_to(-vl[..., :1], b.shape), b, lz], axis=-1)
    kn = lz + nv[..., None]
    # The share of each wavelength's lobe on a read's stretch, a trapezoid: the stretch
    # where the lobe is the narrower, the lobe's box scaled to the stretch where wider.
    half = 0.5 * step
    half_q = np.maximum(np.maximum(half, widen(material, kn)), 1e-30)  # 0 only where v is not
    weight = sum(stretch_weight(material, m, q, half_q, kn)
                 for m in range(1, material.grating_orders + 1))
    scale = np.where(lz > 0.0, 1.0 / np.maximum(np.maximum(lz, nv[..., None]), EPS_DENOM), 0.0)
    scale = scale * half / half_q
    reads_rgb = radiance(lights, footprint(lobe_h, lz, nv[..., None], step))
    total = total + np.sum(weight * scale[..., None] * reads_rgb, axis=-2)
    f = fresnel_schlick(material.f0, nv)
    result: FloatArray = np.where((nv > 0.0)[..., None],
                                  radiance_floor(material.ks * (f * nv)[..., None] * total),
                                  0.0)
    return result
