"""Quadrature of a lobe's density over the hemisphere of half vectors, on a grid fine
where the A-S lobe is narrow: in w = 1 - hz geometrically from 1e-14 (an exponent of
1e6 puts the lobe at w ~ 1e-6), in φ uniformly plus geometric steps toward each
principal axis of every lobe (at ex = 1e6, ey = 0 the lobe's φ profile, 1/(e(φ) + 1),
is 1e-3 wide about the ey axis). dω = dhz dφ = dw dφ.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Density = Callable[[np.ndarray], np.ndarray]  # h (..., 3) -> pdf per unit solid angle


def phi_grid(axes: tuple[float, ...] = (0.0,), extra: tuple[float, ...] = ()) -> np.ndarray:
    """[0, 2π]: uniform, plus points crowding toward ``axes`` + kπ/2 and ``extra``."""
    steps = np.geomspace(1e-9, np.pi / 4, 400)
    points = [np.linspace(0.0, 2 * np.pi, 513), np.asarray(extra, dtype=np.float64)]
    for axis in set(np.round(np.mod(axes, np.pi / 2), 12)):
        for k in range(4):
            centre = axis + k * np.pi / 2
            points.extend([centre + steps, centre - steps, [centre]])
    phi = np.mod(np.concatenate(points), 2 * np.pi)
    return np.unique(np.concatenate([phi, [0.0, 2 * np.pi]]))


def w_grid(extra: tuple[float, ...] = ()) -> np.ndarray:
    """[0, 1], crowding toward 1 too: D is 0 at hz = 0 (the horizon), a step the grid
    has to resolve."""
    near_horizon = 1.0 - np.geomspace(1e-10, 0.5, 100)
    return np.unique(np.concatenate([[0.0, 1.0], np.geomspace(1e-14, 1.0, 800),
                                     near_horizon, extra]))


def half_vectors(phi: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(len(phi), len(w), 3) unit half vectors at the grid's nodes."""
    sin_h = np.sqrt(np.maximum(w * (2.0 - w), 0.0))
    p, s = np.meshgrid(phi, sin_h, indexing="ij")
    return np.stack([s * np.cos(p), s * np.sin(p), np.broadcast_to(1.0 - w, p.shape)], -1)


def cell_masses(density: Density, phi: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(len(phi) - 1, len(w) - 1): each grid cell's ∫ pdf dω, trapezoidal."""
    values = density(half_vectors(phi, w))
    corners = (values[:-1, :-1] + values[1:, :-1] + values[:-1, 1:] + values[1:, 1:]) / 4.0
    return corners * np.diff(phi)[:, None] * np.diff(w)[None, :]


def binned(density: Density, phi_edges: np.ndarray, w_edges: np.ndarray,
           axes: tuple[float, ...]) -> np.ndarray:
    """The probability of each (φ, w) bin whose edges are given: the grid holds the edges,
    so the bins are sums of whole cells."""
    phi = phi_grid(axes, tuple(phi_edges))
    w = w_grid(tuple(w_edges))
    masses = cell_masses(density, phi, w)
    i = np.digitize(0.5 * (phi[:-1] + phi[1:]), phi_edges) - 1
    j = np.digitize(0.5 * (w[:-1] + w[1:]), w_edges) - 1
    out = np.zeros((len(phi_edges) - 1, len(w_edges) - 1))
    np.add.at(out, (i[:, None], j[None, :]), masses)
    return out
