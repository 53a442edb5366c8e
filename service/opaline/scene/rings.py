"""Concentric rings of vertices for the annulus, and the triangles between them.

A uniform grid of ``segments`` angles by a few radii makes every triangle a sliver: the
CD's 128 segments at a thumbnail are 6 px wide at the rim and under 1 px at the hole.
The rasteriser shades a 2×2 quad of pixels once for every triangle that touches it, so
the slivers near the hole had their quads shaded several times over. Here the rings
keep ``segments`` vertices only at the two edges, where the silhouette needs them, and
halve their count in a band beside each edge (each ring one arc of its finer
neighbour away, so the cells stay about square) down to a quarter of ``segments`` over
the middle. The shading does not depend on the mesh inside the edges (flat normal,
planar uv, the tangent computed per fragment from the position), so an image changes
only where the edges' rasterisation rounds differently: on the CD presets at 256², at
most 4 pixels by one 8-bit level, and their renders took about 30 % less time.
"""

from __future__ import annotations

import math

import numpy as np

COARSENINGS = 2  # halvings from the edges' count to the middle's
MIN_COUNT = 8  # no ring is halved below this many vertices


def _arc(radius: float, count: int) -> float:
    return 2.0 * math.pi * radius / count


def ring_plan(inner: float, outer: float, segments: int, rings: int) -> list[tuple[float, int]]:
    """(radius, vertex count) of each ring from ``inner`` to ``outer``: ``segments`` at both
    edges, coarser in between, ``rings`` bands over the middle. Where the edges' bands
    would leave the middle thinner than a cell (a narrow ring, few segments), the uniform
    grid: ``rings`` bands of ``segments``."""
    counts = [segments]
    while len(counts) <= COARSENINGS and counts[-1] // 2 >= MIN_COUNT:
        counts.append(counts[-1] // 2)
    low, high = [(inner, segments)], [(outer, segments)]
    for fine, coarse in zip(counts, counts[1:], strict=False):
        low.append((low[-1][0] + _arc(low[-1][0], fine), coarse))
        high.append((high[-1][0] - _arc(high[-1][0], fine), coarse))
    middle = (low[-1][0], high[-1][0])
    if len(counts) == 1 or middle[1] - middle[0] < _arc(middle[1], counts[-1]):
        return [(float(r), segments) for r in np.linspace(inner, outer, rings + 1)]
    between = np.linspace(*middle, rings + 1)[1:-1]
    return low + [(float(r), counts[-1]) for r in between] + high[::-1]


def zip_rings(first: int, count: int, second: int, next_count: int) -> np.ndarray:
    """Triangles (k, 3) between a ring of ``count`` vertices from index ``first`` and the
    next ring out (``next_count`` from ``second``), both starting at angle 0 and running
    counter-clockwise seen from +y: the two rings' edges taken in the order of the angle
    they end at (this ring's first on a tie), each with the other ring's vertex reached
    so far, so every triangle spans one edge of one ring."""
    ends = np.concatenate([np.arange(1, count + 1) * next_count,
                           np.arange(1, next_count + 1) * count])  # angles × count·next
    outer = np.repeat([False, True], [count, next_count])
    taken = outer[np.lexsort((outer, ends))]
    i = np.cumsum(~taken) - ~taken  # this ring's edges before each one
    j = np.cumsum(taken) - taken  # the next ring's
    a, b = first + i % count, second + j % next_count
    a_next, b_next = first + (i + 1) % count, second + (j + 1) % next_count
    triangles: np.ndarray = np.where(taken[:, None], np.stack([a, b_next, b], 1),
                                     np.stack([a, a_next, b], 1))
    return triangles
