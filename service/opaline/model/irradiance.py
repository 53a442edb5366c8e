"""An environment's irradiance in nine spherical harmonics (Ramamoorthi & Hanrahan 2001),
the diffuse half of environment light, and its float64 evaluation, twin of
``environment_irradiance`` in ``glsl/lib/environment_light.glsl``.

``coefficients`` folds the convolution with the clamped cosine (Â0 = π, Â1 = 2π/3,
Â2 = π/4) and each basis function's constant into one RGB vector per term, so the
shader evaluates a polynomial of the direction in the map's own frame:

    E(d) = c0 + c1·y + c2·z + c3·x + c4·xy + c5·yz + c6·(3z² − 1) + c7·xz + c8·(x² − y²)

Nine terms keep the irradiance within ~3 % of its exact value for any map (their own
paper's bound): irradiance is that smooth.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from opaline.scene.mediancut import directions

FloatArray = npt.NDArray[np.float64]
# Y_lm's constants, in the order above.
Y = np.array([0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392,
              1.092548, 0.546274])
A = np.array([np.pi, *[2 * np.pi / 3] * 3, *[np.pi / 4] * 5])


def basis(d: FloatArray) -> FloatArray:
    """The nine polynomials at unit directions d (..., 3): (..., 9)."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    result: FloatArray = np.stack([np.ones_like(x), y, z, x, x * y, y * z, 3 * z * z - 1,
                                   x * z, x * x - y * y], -1)
    return result


def coefficients(radiance: npt.ArrayLike) -> FloatArray:
    """(9, 3) from an equirectangular map (H, W, 3) of linear radiance (mediancut's layout)."""
    radiance = np.asarray(radiance, dtype=np.float64)
    d, solid = directions(*radiance.shape[:2])
    weighted = radiance * solid[..., None]  # L dω per texel
    # Projection onto Y_lm: Σ L(d) Y_lm(d) dω, then the cosine lobe's Â_l.
    projected = np.einsum("hwk,hwc->kc", basis(d) * Y, weighted)
    result: FloatArray = projected * (A * Y)[:, None]
    return result


def irradiance(coeffs: FloatArray, d: npt.ArrayLike) -> FloatArray:
    """Irradiance (..., 3) on a surface facing unit d (..., 3), in the map's frame."""
    result: FloatArray = np.maximum(basis(np.asarray(d, dtype=np.float64)) @ coeffs, 0.0)
    return result
