"""Float64 twin of ``glsl/lib/lobe_sampling.glsl`` and of the sequence, mixture and quad mean
in ``glsl/lib/environment_light.glsl``: directions drawn from the material's lobe.

Each sampler maps uniforms ``u`` (..., 2) in [0, 1)² to a half vector in the shading
frame and its density per unit solid angle of h. The Ashikhmin-Shirley sampler's
density is eq. 1's D(h) exactly; the multi-peak lobe is sampled through its
envelope hz (uniform over the projected disc).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from opaline.model.microfacet import mdf_ashikhmin

FloatArray = npt.NDArray[np.float64]
R2 = np.array([0.7548776662, 0.5698402910, 0.6180339887])


def sample_ashikhmin(u: npt.ArrayLike, ex: float, ey: float) -> tuple[FloatArray, FloatArray]:
    u = np.asarray(u, dtype=np.float64)
    q = np.minimum(u[..., 0] * 4.0, 3.99999)
    quadrant = np.floor(q)
    f = q - quadrant
    phi = np.arctan(np.sqrt((ex + 1.0) / (ey + 1.0)) * np.tan(0.5 * np.pi * f))
    phi = np.select([quadrant == 1, quadrant == 2, quadrant == 3],
                    [np.pi - phi, np.pi + phi, 2 * np.pi - phi], phi)
    c, s = np.cos(phi), np.sin(phi)
    e = ex * c * c + ey * s * s
    one_minus_hz = -np.expm1(np.log1p(-u[..., 1]) / (e + 1.0))
    sin_h = np.sqrt(np.maximum(one_minus_hz * (2.0 - one_minus_hz), 0.0))
    h = np.stack([sin_h * c, sin_h * s, 1.0 - one_minus_hz], -1)
    return h, mdf_ashikhmin(h[..., 0], h[..., 1], h[..., 2], ex, ey)


def sample_projected_disc(u: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    u = np.asarray(u, dtype=np.float64)
    r = np.sqrt(u[..., 0])
    phi = 2 * np.pi * u[..., 1]
    hz = np.sqrt(np.maximum(1.0 - u[..., 0], 0.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), hz], -1), hz / np.pi


def rotated_mixture(u: npt.ArrayLike, ex: float, ey: float,
                    thetas: tuple[float, float, float]) -> tuple[FloatArray, FloatArray]:
    """The rotation colour source's sampler: u (..., 3); u[..., 2] picks the channel whose
    lobe (eq. 1's turned by -θc) is sampled; the density is the three lobes' mean."""
    u = np.asarray(u, dtype=np.float64)
    channel = np.minimum((u[..., 2] * 3.0).astype(int), 2)
    s, _ = sample_ashikhmin(u[..., :2], ex, ey)
    theta = np.asarray(thetas)[channel]
    c, sn = np.cos(theta), np.sin(theta)
    h = np.stack([c * s[..., 0] + sn * s[..., 1], c * s[..., 1] - sn * s[..., 0], s[..., 2]], -1)
    return h, mixture_density(h, ex, ey, thetas)


def mixture_density(h: FloatArray, ex: float, ey: float,
                    thetas: tuple[float, float, float]) -> FloatArray:
    total = np.zeros(h.shape[:-1])
    for theta in thetas:
        c, s = np.cos(theta), np.sin(theta)
        hx, hy = c * h[..., 0] - s * h[..., 1], s * h[..., 0] + c * h[..., 1]
        total = total + mdf_ashikhmin(hx, hy, h[..., 2], ex, ey)
    result: FloatArray = total / len(thetas)
    return result


def sequence(k: npt.ArrayLike, shift: npt.ArrayLike = (0.0, 0.0, 0.0)) -> FloatArray:
    """Sample k of a pixel's sequence (R2, Roberts 2018, and a third dimension)."""
    n = np.asarray(k, dtype=np.float64)[..., None] + 0.5
    result: FloatArray = np.mod(np.asarray(shift) + n * R2, 1.0)
    return result


def pixel_shift(x: npt.ArrayLike, y: npt.ArrayLike) -> FloatArray:
    """A pixel's shift of its sequence, from an integer hash of its coordinates, as
    ``env_pixel_shift`` in glsl/lib/environment_light.glsl: (..., 3) in [0, 1)."""
    def mix(h: np.ndarray) -> np.ndarray:
        mixed: np.ndarray = ((h ^ (h >> 16)) * np.uint64(0x45D9F3B)) & np.uint64(0xFFFFFFFF)
        return mixed

    h = (np.asarray(x, dtype=np.uint64) * np.uint64(1973) + np.asarray(y, dtype=np.uint64)
         * np.uint64(9277) + np.uint64(26699)) & np.uint64(0xFFFFFFFF)
    h = mix(mix(h))
    h ^= h >> 16
    result: FloatArray = np.stack([(h & np.uint64(1023)).astype(np.float64) / 1024.0,
                                   ((h >> 10) & np.uint64(1023)).astype(np.float64) / 1024.0,
                                   (h >> 20).astype(np.float64) / 4096.0], axis=-1)
    return result


def quad_means(image: npt.ArrayLike) -> FloatArray:
    """Every pixel of ``image`` (rows, columns, channels; an even number of rows and of
    columns) as the mean over its 2×2 quad, as ``quad_mean`` pools the rotation source's
    map samples: GL's quads start at even window coordinates, and with an even height the
    image's rows, stored top first, pair up the same way."""
    data = np.asarray(image, dtype=np.float64)
    rows, cols = data.shape[:2]
    if rows % 2 or cols % 2:
        raise ValueError(f"quads need an even size, not {rows}×{cols}")
    means = data.reshape(rows // 2, 2, cols // 2, 2, -1).mean(axis=(1, 3))
    result: FloatArray = means.repeat(2, axis=0).repeat(2, axis=1).reshape(data.shape)
    return result
