"""The product-shot environments, procedural and closed form: ``studio`` and ``neutral``.

``studio`` follows the idea of three.js's ``RoomEnvironment``: the object stands in
a box-shaped room whose grey walls, floor and ceiling are lit by one lamp above it
(so each face carries a gentle gradient, as a real room does), with emissive
soft-box panels of several sizes and brightnesses on the faces, the largest and
brightest (the key) on the ceiling above and in front of the object, and one small
hard light (``SPOT_*``). Each texel
traces its direction from the object to the room's box and reads the face it hits:
a glossy object shows the walls as gradients and the panels as sharp rectangles.
Texels are averaged over 2×2 sub-directions, so panel edges are anti-aliased.

``neutral`` is a soft grey gradient, brighter above, darker below, with no
features: a calm backdrop and even light.

Both are fixed-size float32 maps in ``mediancut``'s convention, built once per
process (``studio`` at 256×512 takes ~0.1 s) and kept read-only.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from opaline.scene.mediancut import directions

STUDIO_SIZE = (256, 512)  # 0.7° per texel: the panels' edges stay sharp behind the object
NEUTRAL_SIZE = (128, 256)  # no features to resolve
SUPERSAMPLE = 2
# The room, in units of the object's radius: the object stands a little above the floor,
# nearer the floor than the ceiling, as on a product table.
LOW = np.array([-2.5, -1.0, -2.5])
HIGH = np.array([2.5, 2.0, 2.5])
LAMP = np.array([0.0, 0.8, 0.3])  # the point light that gives the faces their gradient
LAMP_POWER = 0.25  # the faces' radiance per unit cosine over squared distance
FACE_BASE = 0.02  # light bounced around the room: no face goes black
# Albedo per face, in the order of _faces' index: -x, +x, -y (floor), +y, -z, +z.
ALBEDO = np.array([0.8, 0.8, 0.55, 0.9, 0.8, 0.8])
# The whole room's level. Glossy films show the room, not the light it casts: at the
# earlier studio's irradiance (level 1) the gallery's objects sat at L* 14-27 and its
# films near black; at 2.5 they sit where a product shot exposes them (docs/gallery.md).
LEVEL = 2.5


class Panel(NamedTuple):
    """An emissive rectangle on one face of the room: ``axis`` (0 x, 1 y, 2 z) and
    ``side`` (-1 low, +1 high) name the face; ``a`` and ``b`` bound it along the face's
    other two axes in increasing order; ``radiance`` is its linear RGB."""

    axis: int
    side: int
    a: tuple[float, float]
    b: tuple[float, float]
    radiance: tuple[float, float, float]


# A hard light: a small round source above, in front and to the left, as a product shot
# adds to the soft boxes to give glossy and diffracting surfaces a sharp highlight. The
# soft boxes alone light the multi-peak lobe (a CD, the paper's Fig. 9 material) so
# evenly that its bands average to grey (the brute-force reference agrees), where a
# photograph of a CD under a lamp shows its rainbow. Its irradiance is the key panel's
# order (~3), from 1.5° of arc, so split_bright makes it one directional light.
SPOT_DIRECTION = (-0.55, 0.62, 0.56)
SPOT_RADIUS_DEG = 1.5
SPOT_IRRADIANCE = (3.0, 2.95, 2.85)  # warm white, W/m² in the map's units

PANELS = (
    Panel(1, +1, (0.3, 2.1), (0.5, 2.1), (2.3, 2.25, 2.15)),    # key: ceiling, above-front right
    Panel(0, -1, (-0.6, 1.8), (-0.5, 0.35), (0.86, 0.9, 0.98)),  # strip: tall, on the left wall
    Panel(0, +1, (0.0, 1.4), (-1.8, 0.2), (0.33, 0.33, 0.33)),  # fill: large, dim, right wall
    Panel(2, +1, (-1.7, -0.5), (0.1, 1.3), (0.96, 0.96, 0.96)),    # front: behind the camera
    Panel(2, -1, (0.1, 1.5), (0.4, 1.2), (0.72, 0.72, 0.74)),     # rim: behind the object
    Panel(1, +1, (-1.8, -0.7), (-1.9, -0.8), (0.6, 0.6, 0.6)),  # small: ceiling, back left
)


def _hits(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each direction from the origin meets the room's box, and which face
    (0..5: -x, +x, -y, +y, -z, +z)."""
    with np.errstate(divide="ignore"):
        bound = np.where(d > 0, HIGH, LOW) / d  # distance to each axis's wall (inf if parallel)
    bound = np.where(np.isfinite(bound) & (bound > 0), bound, np.inf)
    axis = bound.argmin(-1)
    t = np.take_along_axis(bound, axis[..., None], -1)
    point = d * t
    side = np.take_along_axis(d, axis[..., None], -1)[..., 0] > 0
    return point, axis * 2 + side


def _faces(point: np.ndarray, face: np.ndarray) -> np.ndarray:
    """Radiance of the room's grey faces: bounce light plus the lamp's, cosine over
    squared distance, toward the inward normal."""
    axis, high = face // 2, face % 2 == 1
    normal = np.zeros_like(point)
    np.put_along_axis(normal, axis[..., None], np.where(high, -1.0, 1.0)[..., None], -1)
    to_lamp = LAMP - point
    r2 = (to_lamp ** 2).sum(-1)
    cosine = np.clip((normal * to_lamp).sum(-1) / np.sqrt(r2), 0.0, 1.0)
    grey = ALBEDO[face] * (FACE_BASE + LAMP_POWER * cosine / r2)
    paint: np.ndarray = grey[..., None] * np.array([1.0, 0.99, 0.97])  # warm white
    return paint


def _panels(point: np.ndarray, face: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    for panel in PANELS:
        u, v = [k for k in range(3) if k != panel.axis]
        inside = ((face == panel.axis * 2 + (panel.side > 0))
                  & (point[..., u] >= panel.a[0]) & (point[..., u] <= panel.a[1])
                  & (point[..., v] >= panel.b[0]) & (point[..., v] <= panel.b[1]))
        radiance = np.where(inside[..., None], np.asarray(panel.radiance), radiance)
    return radiance


def _downsample(fine: np.ndarray) -> np.ndarray:
    h, w = fine.shape[0] // SUPERSAMPLE, fine.shape[1] // SUPERSAMPLE
    blocks = fine.reshape(h, SUPERSAMPLE, w, SUPERSAMPLE, fine.shape[2])
    averaged: np.ndarray = blocks.mean((1, 3))
    return averaged


def _spot(d: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    axis = np.asarray(SPOT_DIRECTION) / np.linalg.norm(SPOT_DIRECTION)
    cos_radius = np.cos(np.radians(SPOT_RADIUS_DEG))
    solid = 2.0 * np.pi * (1.0 - cos_radius)
    inside = (d @ axis) >= cos_radius
    return np.where(inside[..., None], np.asarray(SPOT_IRRADIANCE) / solid, radiance)


@lru_cache(maxsize=1)
def studio() -> np.ndarray:
    d, _ = directions(STUDIO_SIZE[0] * SUPERSAMPLE, STUDIO_SIZE[1] * SUPERSAMPLE)
    point, face = _hits(d)
    radiance = _spot(d, _panels(point, face, _faces(point, face)) * LEVEL)
    return _frozen(_downsample(radiance))


@lru_cache(maxsize=1)
def neutral() -> np.ndarray:
    d, _ = directions(*NEUTRAL_SIZE)
    # Smooth in the direction's height: light grey overhead, fading through the horizon
    # to a darker floor, as a seamless paper backdrop.
    g = (0.5 + 0.5 * d[..., 1:2]) ** 1.5
    below, above = np.array([0.05, 0.05, 0.052]), np.array([0.42, 0.42, 0.43])
    return _frozen(below + (above - below) * g)


def _frozen(radiance: np.ndarray) -> np.ndarray:
    """Float32 and read-only: the one copy is shared by every caller."""
    out = np.ascontiguousarray(radiance, dtype=np.float32)
    out.flags.writeable = False
    return out
