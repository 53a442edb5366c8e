"""What a linear render or shading value promises now that a colour outside sRGB keeps a
channel below 0 (docs/physics.md §1.4, "Gamut"): finite, and its luminance not below 0.
Coverage (alpha), where there is one, is not below 0 either."""

from __future__ import annotations

import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # linear sRGB's Y row (IEC 61966-2-1)


def luminance(rgb: np.ndarray) -> np.ndarray:
    return np.asarray(rgb, dtype=np.float64)[..., :3] @ LUMINANCE


def radiance_problems(image: np.ndarray) -> str | None:
    """Why ``image`` (…, 3 or 4) is not a radiance, or None: non-finite values, a luminance
    below 0 beyond float32 rounding, a negative coverage."""
    image = np.asarray(image, dtype=np.float64)
    bad = ~np.isfinite(image)
    if bad.any():
        return f"{int(bad.sum())} non-finite values, first at {np.argwhere(bad)[0]}"
    y = luminance(image)
    tolerance = 1e-6 * (1.0 + float(np.abs(image[..., :3]).max(initial=0.0)))
    if (y < -tolerance).any():
        return f"luminance below 0: min {y.min():.3g} at {np.argwhere(y < -tolerance)[0]}"
    if image.shape[-1] == 4 and (image[..., 3] < 0).any():
        return f"negative coverage, min {image[..., 3].min():.3g}"
    return None


def is_radiance(image: np.ndarray) -> bool:
    return radiance_problems(image) is None
