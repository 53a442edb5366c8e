"""An environment's small, very bright features (a sun, a spot lamp) split off as
directional lights, so that reading the map by lobe samples never meets them.

A lobe sample that lands on a sun 1e5 times brighter than the sky is a firefly:
a few samples a pixel cannot average it out. Texels brighter than
``BRIGHT_OVER_MEAN`` times the map's mean luminance keep that threshold's
luminance in the map (hue kept), and what they had above it becomes at most
``MAX_LIGHTS`` directional lights by median cut. The map and the lights together
carry exactly the original map's energy. Soft boxes of a studio (about 20 times
its mean) stay in the map, where their shape is reflected; the built-in sky's sun
(2400, about 10⁴ times) and an HDR photograph's sun become lights.
"""

from __future__ import annotations

import numpy as np

from opaline.scene.mediancut import LUMA, directions, median_cut

BRIGHT_OVER_MEAN = 50.0
MAX_LIGHTS = 4
MERGE_DEGREES = 3.0


def split_bright(radiance: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(the map with its bright texels capped, light directions (K, 3), irradiances (K, 3)),
    K ≤ ``MAX_LIGHTS``; K = 0 when nothing is over the threshold."""
    none = np.zeros((0, 3))
    luma = radiance.astype(np.float64) @ LUMA
    _, solid = directions(*radiance.shape[:2])
    mean = float((luma * solid).sum() / (4 * np.pi))
    threshold = BRIGHT_OVER_MEAN * mean
    if mean <= 0.0 or float(luma.max()) <= threshold:
        return radiance, none, none
    scale = np.minimum(1.0, threshold / np.maximum(luma, 1e-30))[..., None]
    kept = (radiance * scale).astype(np.float32)
    direction, irradiance = median_cut(radiance - kept, MAX_LIGHTS)
    direction, irradiance = merge_close(direction, irradiance)
    return kept, direction, irradiance


def merge_close(direction: np.ndarray, irradiance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lights within ``MERGE_DEGREES`` of a brighter one folded into it (energy-weighted
    direction, summed irradiance): median cut splits one small source (a sun of 0.5°)
    into up to MAX_LIGHTS lights a fraction of a degree apart, each a full evaluation of
    the reflectance, where one light at their centroid lights every lobe the same to
    within the source's own size."""
    order = np.argsort(-(irradiance @ LUMA), kind="stable")
    cos_limit = np.cos(np.radians(MERGE_DEGREES))
    groups: list[list[int]] = []
    for index in order:
        home = next((g for g in groups if direction[g[0]] @ direction[index] >= cos_limit), None)
        if home is None:
            groups.append([int(index)])
        else:
            home.append(int(index))
    merged_d, merged_e = [], []
    for group in groups:
        weight = irradiance[group] @ LUMA
        d = (direction[group] * np.maximum(weight, 1e-30)[:, None]).sum(0)
        merged_d.append(d / np.linalg.norm(d))
        merged_e.append(irradiance[group].sum(0))
    return np.array(merged_d).reshape(-1, 3), np.array(merged_e).reshape(-1, 3)
