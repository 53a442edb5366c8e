"""CIE L*a*b* (D65 white) of display-encoded sRGB, as colour-science computes it, without
importing it: the package's runtime dependencies do not include colour-science, and the
gallery (``opaline gallery``) reports each picture's chroma from the package alone.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from opaline.model.display import srgb_decode
from opaline.model.microfacet import FloatArray

# Linear sRGB → XYZ as IEC 61966-2-1 prints it (4 digits), the matrix colour-science
# uses, so these figures equal bench/metrics.py's; the white is D65's chromaticity.
SRGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                        [0.0193, 0.1192, 0.9505]])
D65_XY = np.array([0.3127, 0.3290])


def xy_to_xyz(xy: npt.ArrayLike) -> FloatArray:
    """Chromaticity (x, y) → XYZ with Y = 1."""
    x, y = np.asarray(xy, dtype=np.float64).T
    return np.stack([x / y, np.ones_like(x), (1.0 - x - y) / y], axis=-1)


WHITE_XYZ = xy_to_xyz(D65_XY[None])[0]
EPSILON = 216.0 / 24389.0
KAPPA = 24389.0 / 27.0


def srgb_to_lab(rgb: npt.ArrayLike) -> FloatArray:
    """Display sRGB in [0, 1] (last axis R, G, B; clipped) → L*, a*, b* on the last axis."""
    linear = srgb_decode(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0))
    ratio = (linear @ SRGB_TO_XYZ.T) / WHITE_XYZ
    f = np.where(ratio > EPSILON, np.cbrt(ratio), (KAPPA * ratio + 16.0) / 116.0)
    return np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]),
                     200.0 * (f[..., 1] - f[..., 2])], axis=-1)


def chroma(lab: npt.ArrayLike) -> FloatArray:
    """C*ab: the distance from the grey axis in the a*b* plane."""
    lab = np.asarray(lab, dtype=np.float64)
    return np.asarray(np.hypot(lab[..., 1], lab[..., 2]))
