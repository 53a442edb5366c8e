"""The microfacet pieces the paper's model and the physical sources share, in float64.

The Ashikhmin–Shirley distribution (eq. 1) with its guard at the pole, Schlick's
Fresnel, and the clamps every shading function uses (docs/design.md §2). Both
``reference`` (the paper's model) and ``physical`` (thin film, grating) build on
these, so they live below both.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
import numpy.typing as npt

# The reference computes in float64 throughout.
FloatArray: TypeAlias = npt.NDArray[np.float64]
# Shading inputs broadcast: a value is an array or a plain number (a material's constant).
Values: TypeAlias = FloatArray | float
# A shading frame: tangent, bitangent and normal, each (..., 3).
Frame: TypeAlias = tuple[FloatArray, FloatArray, FloatArray]

EPS_DENOM = 1e-4  # docs/design.md §2: every denominator clamped to at least this
EPS_HALF = 1e-6  # |l + v| below this: no half vector, no specular
TWO_PI = 2.0 * np.pi


def log1p_ratio(s2: npt.ArrayLike) -> FloatArray:
    """-log1p(-s2) / s2, which is 1 at s2 = 0 and grows to the rim.

    ``hz**e = exp(e * ln hz)`` with ``ln hz = 0.5 * log1p(-s2)``; dividing by s2
    here lets the A-S exponent be written from hx², hy² alone (docs/design.md §2).
    """
    s2 = np.asarray(s2, dtype=np.float64)
    u = np.clip(1.0 - s2, 1e-12, 1.0)
    safe = np.where(s2 > 0.0, s2, 1.0)
    return np.where(s2 > 0.0, -np.log(u) / safe, 1.0)


def mdf_ashikhmin(hx: Values, hy: Values, hz: Values, ex: float, ey: float) -> FloatArray:
    """Eq. 1: sqrt((ex+1)(ey+1))/(2π) · hz^((ex·hx² + ey·hy²)/(hx² + hy²))."""
    hx2, hy2 = hx * hx, hy * hy
    s2 = np.minimum(hx2 + hy2, 1.0)
    log_term = -0.5 * (ex * hx2 + ey * hy2) * log1p_ratio(s2)
    norm = np.sqrt((ex + 1.0) * (ey + 1.0)) / TWO_PI
    return np.where(hz > 0.0, norm * np.exp(log_term), 0.0)


def fresnel_schlick(f0: Values, cos_theta: Values) -> Values:
    cos_theta = np.clip(cos_theta, 0.0, 1.0)
    return f0 + (1.0 - f0) * (1.0 - cos_theta) ** 5
