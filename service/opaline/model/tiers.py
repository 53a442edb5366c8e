"""The named quality tiers: each a bundle of samples, wavelengths and anti-aliasing,
chosen from the measured speed/accuracy fronts (docs/accuracy.md)."""

from __future__ import annotations

# What each quality tier means; a request may override any field of it.
TIERS: dict[str, dict[str, object]] = {
    # Points on the measured fronts (docs/accuracy.md), one bundle for every preset. On most
    # presets the RGB model's own error outweighs one sample's aliasing, so the cheap tiers
    # buy wavelengths before samples: one sample of 8 wavelengths, band-limited, costs
    # little more than one RGB sample and has a third to half of its error.
    "draft": {"samples": 1, "wavelengths": 8, "aa": "analytic"},
    # FLIP <= 0.05 on every preset at about 1.5x draft's time.
    "standard": {"samples": 1, "wavelengths": 16, "aa": "analytic"},
    # FLIP <= 0.01 on every preset; the wavelengths move between samples (spectrum.py).
    "high": {"samples": 8, "wavelengths": 16, "aa": "none"},
    # The converged target: brute force, no analytic approximation; within FLIP 0.01 of twice
    # its samples and wavelengths even at theta = ±2π.
    "reference": {"samples": 64, "wavelengths": 32, "aa": "none"},
}
