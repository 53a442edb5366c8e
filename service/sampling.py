"""Deterministic sub-pixel sample positions, so the same request gives the same bytes."""

from __future__ import annotations

import numpy as np

# Roberts' R2 sequence: the plastic number's reciprocals give a low-discrepancy
# 2-D sequence whose first n points cover the pixel well for every n.
_G = 1.32471795724474602596
_A = np.array([1.0 / _G, 1.0 / (_G * _G)])


def sample_offsets(count: int) -> np.ndarray:
    """(count, 2) offsets in pixels within [-0.5, 0.5); one sample sits at the centre."""
    if count <= 1:
        return np.zeros((1, 2))
    k = np.arange(count)[:, None]
    return np.mod(0.5 + k * _A, 1.0) - 0.5
