"""An environment map turned into K directional lights by median cut (Debevec 2005).

The equirectangular map is split, region by region, at the median of its
energy (radiance × solid angle, by luminance) across the region's longer
side (in angle, so regions near the poles are not split into slivers),
until there are K regions; each becomes one directional light at its
energy's centroid, carrying the region's whole irradiance ∫L dω (RGB). The
lights' sum is the map's total, whatever K, and as K grows each light's
region shrinks, so a render converges to the map's integral: K is the
quality knob, measured like every other (docs/accuracy.md).

Map convention: row 0 is the zenith, rows run down to the nadir; column c
is azimuth φ = 2π (c + ½) / W, direction (cos φ cos e, sin e, sin φ cos e), the
key light's azimuth convention (``atan2(z, x)``).
"""

from __future__ import annotations

import heapq

import numpy as np

LUMA = np.array([0.2126, 0.7152, 0.0722])


def directions(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit direction (H, W, 3) of each texel's centre, and its solid angle (H, 1)."""
    elevation = np.pi / 2 - (np.arange(height) + 0.5) * np.pi / height
    azimuth = (np.arange(width) + 0.5) * 2 * np.pi / width
    e, a = np.meshgrid(elevation, azimuth, indexing="ij")
    d = np.stack([np.cos(a) * np.cos(e), np.sin(e), np.sin(a) * np.cos(e)], -1)
    band = np.cos(elevation)  # a texel's solid angle ∝ cos(elevation)
    solid = (2 * np.pi / width) * (np.pi / height) * band[:, None]
    return d, solid


def median_cut(radiance: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` lights: unit directions (K, 3) toward each, and their irradiance (K, 3).

    The region with the most energy is split next (not every region each round), so K
    need not be a power of two and bright features get lights first. Fewer than
    ``count`` come back only if the map has fewer texels with energy; a black map gives
    one light of irradiance 0."""
    height, width = radiance.shape[:2]
    d, solid = directions(height, width)
    power = radiance.astype(np.float64) * solid[..., None]  # (H, W, 3): ∫L dω per texel
    energy = power @ LUMA
    cumulative = energy.cumsum(0).cumsum(1)  # summed-area table for region energies

    def total(r0: int, r1: int, c0: int, c1: int) -> float:
        s = cumulative[r1 - 1, c1 - 1]
        if r0:
            s -= cumulative[r0 - 1, c1 - 1]
        if c0:
            s -= cumulative[r1 - 1, c0 - 1]
        if r0 and c0:
            s += cumulative[r0 - 1, c0 - 1]
        return float(s)

    regions = [(-total(0, height, 0, width), 0, height, 0, width)]
    done: list[tuple[int, int, int, int]] = []
    while regions and len(regions) + len(done) < count:
        _, r0, r1, c0, c1 = heapq.heappop(regions)
        # Angular extent: a column spans less angle near the poles.
        mid = (r0 + r1) / 2
        band = np.cos(np.pi / 2 - mid * np.pi / height)
        rows_wide = (r1 - r0) * np.pi / height
        cols_wide = (c1 - c0) * 2 * np.pi / width * band
        split_rows = rows_wide >= cols_wide
        if (r1 - r0 < 2 and split_rows) or (c1 - c0 < 2 and not split_rows):
            split_rows = not split_rows
        if (r1 - r0 < 2) and (c1 - c0 < 2):
            done.append((r0, r1, c0, c1))
            continue
        block = energy[r0:r1, c0:c1]
        profile = block.sum(1) if split_rows else block.sum(0)
        running = np.cumsum(profile)
        cut = int(np.searchsorted(running, running[-1] / 2)) + 1
        cut = min(max(cut, 1), len(profile) - 1)
        halves = ([(r0, r0 + cut, c0, c1), (r0 + cut, r1, c0, c1)] if split_rows
                  else [(r0, r1, c0, c0 + cut), (r0, r1, c0 + cut, c1)])
        for half in halves:
            heapq.heappush(regions, (-total(*half), *half))
    lights_d, lights_e = [], []
    for region in done + [r[1:] for r in regions]:
        r0, r1, c0, c1 = region
        p = power[r0:r1, c0:c1].reshape(-1, 3)
        w = energy[r0:r1, c0:c1].reshape(-1)
        if w.sum() <= 0.0:
            continue
        centroid = (d[r0:r1, c0:c1].reshape(-1, 3) * w[:, None]).sum(0)
        norm = np.linalg.norm(centroid)
        if norm <= 0.0:
            continue
        lights_d.append(centroid / norm)
        lights_e.append(p.sum(0))
    if not lights_d:
        # A black map: one light carrying nothing, for GLSL has no empty arrays (a
        # LIGHT_COUNT of 0 does not compile).
        lights_d, lights_e = [np.array([0.0, 1.0, 0.0])], [np.zeros(3)]
    return np.array(lights_d).reshape(-1, 3), np.array(lights_e).reshape(-1, 3)
