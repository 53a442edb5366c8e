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


def zip_rings(first: int, count: int, second: int, next_count: int) -> list[tuple[int, int, int]]:
    """Triangles between a ring of ``count`` vertices from index ``first`` and the next
    ring out (``next_count`` from ``second``), both starting at angle 0 and running
    counter-clockwise seen from +y: walk both by angle, always advancing the one whose
    next vertex comes first, so every triangle spans one edge of one ring."""
    triangles = []
    i = j = 0
    while i < count or j < next_count:
        if j == next_count or (i < count and (i + 1) * next_count <= (j + 1) * count):
            triangles.append((first + i, first + (i + 1) % count, second + j % next_count))
            i += 1
        else:
            triangles.append((first + i % count, second + (j + 1) % next_count, second + j))
            j += 1
    return triangles
