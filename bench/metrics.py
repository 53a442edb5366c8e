"""Image error metrics on display images: PSNR, CIEDE2000 statistics, FLIP.

Every function takes two display images (sRGB-encoded, values in [0, 1],
H×W×3 or H×W×4; alpha is ignored), the reference first. Shared by
``bench/accuracy.py`` and ``tests/gl/test_quality.py``.
"""

from __future__ import annotations

import math

import numpy as np


def _rgb(image: np.ndarray) -> np.ndarray:
    return np.clip(np.asarray(image, dtype=np.float64)[..., :3], 0.0, 1.0)


def psnr(reference: np.ndarray, test: np.ndarray) -> float:
    """Peak signal-to-noise ratio in dB over R, G, B (peak 1); ``inf`` for equal images."""
    mse = float(np.mean((_rgb(reference) - _rgb(test)) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def srgb_to_lab(image: np.ndarray) -> np.ndarray:
    """Display sRGB → XYZ (D65) → CIE L*a*b* (D65 white)."""
    import colour

    with colour.utilities.suppress_warnings(colour_usage_warnings=True):
        xyz = colour.sRGB_to_XYZ(_rgb(image))
        white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
        return colour.XYZ_to_Lab(xyz, white)


def delta_e2000(reference: np.ndarray, test: np.ndarray) -> np.ndarray:
    """Per-pixel CIEDE2000 colour difference, H×W."""
    import colour

    return colour.delta_E(srgb_to_lab(reference), srgb_to_lab(test), method="CIE 2000")


def delta_e2000_stats(reference: np.ndarray, test: np.ndarray) -> tuple[float, float]:
    """(mean, 95th percentile) of the per-pixel CIEDE2000 difference."""
    de = delta_e2000(reference, test)
    return float(np.mean(de)), float(np.percentile(de, 95.0))


def flip(reference: np.ndarray, test: np.ndarray) -> float:
    """Mean LDR-FLIP error (NVIDIA's flip-evaluator, default 67 pixels per degree)."""
    import flip_evaluator

    ref = np.ascontiguousarray(_rgb(reference), dtype=np.float32)
    out = np.ascontiguousarray(_rgb(test), dtype=np.float32)
    _, mean, _ = flip_evaluator.evaluate(ref, out, "LDR", inputsRGB=True, applyMagma=False)
    return float(mean)


def all_metrics(reference: np.ndarray, test: np.ndarray) -> dict[str, float]:
    """PSNR, ΔE2000 mean and p95, FLIP: the columns of the accuracy table."""
    de_mean, de_p95 = delta_e2000_stats(reference, test)
    return {"psnr_db": psnr(reference, test), "de2000_mean": de_mean, "de2000_p95": de_p95,
            "flip": flip(reference, test)}
