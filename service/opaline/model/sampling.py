"""Deterministic sub-pixel sample positions, so the same request gives the same bytes."""

from __future__ import annotations

import numpy as np

# Roberts' R2 sequence: the plastic number's reciprocals give a low-discrepancy
# 2-D sequence whose first n points cover the pixel well for every n.
_G = 1.32471795724474602596
_A = np.array([1.0 / _G, 1.0 / (_G * _G)])


def sample_offsets(count: int) -> np.ndarray:
    """(count, 2) offsets in pixels, centred on the pixel; one sample sits at the centre.

    The first n points of R2 do not average to the centre (the first 4 to about
    (-0.12, -0.15) px), which would shift every supersampled image, so the set is
    re-centred; a point may then lie up to ~0.15 px outside the pixel.
    """
    if count <= 1:
        return np.zeros((1, 2))
    k = np.arange(count)[:, None]
    offsets = np.mod(0.5 + k * _A, 1.0) - 0.5
    centred: np.ndarray = offsets - offsets.mean(axis=0)
    return centred
