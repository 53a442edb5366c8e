"""Procedural tangent-space normal maps, reproducible from a seed.

A map is an ``(H, W, 3)`` float32 array of unit normals in tangent space,
stored as images are: row 0 is the top of the picture (``v = 1``), column 0 its
left edge (``u = 0``). Components follow the OpenGL ("green up") convention the
shader's frame ``(t, cross(n, t), n)`` expects: x along +u (the tangent), y
along +v (so toward row 0), z out of the surface, toward the viewer. Uploading
to a texture whose first row is ``v = 0`` therefore needs a vertical flip,
exactly as for a normal map read from a file.

The procedural maps are built from a height field's analytic gradient, so
they are integrable (no impossible "twisted" normals) and tile: bumps and cells
wrap around the edges, because meshes such as the box reuse the full [0, 1]
square on every face and a wrapped texture sampler shows any seam.

Same seed, same bytes: everything random comes from one ``numpy.random.Generator``
seeded with ``seed``, drawn in a fixed order.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from opaline.scene import generators

RESOLUTION = (8, 8192)
SEED = (0, 2**63 - 1)

# Scales a bump of profile R (1 - (d/R)²)² so that its steepest slope is 1.
_BUMP_PEAK = 3.0 * math.sqrt(3.0) / 8.0


def _from_gradient(gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """Unit normals of a height field given dh/dx (x right) and dh/dy (y down, image rows).

    ``n ∝ (-dh/du, -dh/dv, 1)`` with ``u = x`` and ``v = 1 - y``.
    """
    n = np.stack([-gx, gy, np.ones_like(gx)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return n.astype(np.float32)


def _wrap(t: np.ndarray) -> np.ndarray:
    """Shortest signed offset on the unit torus, which is what makes the maps tile."""
    return (t + 0.5) % 1.0 - 0.5


def _texels_within(centre: float, r: float, resolution: int) -> np.ndarray:
    """Unwrapped indices k with texel centre (k + 0.5)/resolution within r of centre.

    At most 2·r·resolution + 1 of them, so for r < 0.5 no two wrap to one texel
    (a repeated index would drop a contribution in ``a[idx] -= ...``).
    """
    lo = math.ceil((centre - r) * resolution - 0.5)
    hi = math.floor((centre + r) * resolution - 0.5)
    return np.arange(lo, hi + 1)


def bumps(
    resolution: int = 512,
    seed: int = 1,
    count: int = 60,
    radius: tuple[float, float] = (0.03, 0.12),
    strength: float = 1.0,
) -> np.ndarray:
    """Random smooth round bumps, the perturbed cube of the paper's Fig. 10a.

    Each bump is ``R (1 - (d/R)²)²`` with ``R`` drawn from ``radius`` (in
    texture widths): it meets the flat surface with zero slope, so bumps have no
    visible rims, and its height scales with its radius, so small and large
    bumps look equally steep. ``strength`` is that steepest slope (1 = 45°);
    overlapping bumps add up and may be steeper. Bumps wrap around the edges.
    """
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    seed = generators.integer("seed", seed, *SEED)
    count = generators.integer("count", count, 0, 10_000)
    if isinstance(radius, str | bytes) or not isinstance(radius, Sequence | np.ndarray):
        raise ValueError(f"argument 'radius' must be a (min, max) pair, got {radius!r}")
    if len(radius) != 2:
        raise ValueError(f"argument 'radius' must be a (min, max) pair, got {len(radius)} values")
    r_min = generators.real("radius", radius[0], 0.0, 0.5)
    r_max = generators.real("radius", radius[1], 0.0, 0.5)
    if not 0.0 < r_min <= r_max < 0.5:
        raise ValueError(f"argument 'radius' needs 0 < min <= max < 0.5, got {tuple(radius)}")
    strength = generators.real("strength", strength, 0.0, 100.0)

    rng = np.random.default_rng(seed)
    centres = rng.random((count, 2))
    radii = rng.uniform(r_min, r_max, count)

    gx = np.zeros((resolution, resolution))
    gy = np.zeros((resolution, resolution))
    scale = 4.0 * strength * _BUMP_PEAK
    # One small window per bump rather than count × H × W distances; windows
    # are narrower than the texture (R < 0.5), so wrapped indices never repeat.
    for (cx, cy), r in zip(centres, radii, strict=True):
        cols = _texels_within(cx, r, resolution)
        rows = _texels_within(cy, r, resolution)
        dx = (cols + 0.5) / resolution - cx
        dy = (rows + 0.5) / resolution - cy
        # dh/dd · (dx, dy)/d = -4 (1 - q²) (dx, dy) / R per unit of peak slope.
        w = np.maximum(1.0 - (dy[:, None] ** 2 + dx[None, :] ** 2) / (r * r), 0.0) * (scale / r)
        window = np.ix_(rows % resolution, cols % resolution)
        gx[window] -= w * dx[None, :]
        gy[window] -= w * dy[:, None]
    return _from_gradient(gx, gy)


def nacre(
    resolution: int = 512,
    seed: int = 1,
    cells: int = 90,
    tilt: float = 0.35,
    ripple: float = 0.08,
    ripple_frequency: float = 60.0,
) -> np.ndarray:
    """Mother-of-pearl: tilted platelets with growth lines, as in the paper's Fig. 10c.

    Platelets are the Voronoi cells of ``cells`` random sites on the torus.
    Each is a plane whose slope is drawn uniformly from the disc of radius
    ``tilt``, so neighbouring platelets catch the light at different angles and
    the iridescence breaks up into patches. Inside each, concentric sines
    around the site (``ripple_frequency`` rings per texture width, peak slope
    ``ripple``, random phase per cell) imitate the growth lines. Rings finer
    than ``resolution / 4`` are faded out, and gone at ``resolution / 2``.
    """
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    seed = generators.integer("seed", seed, *SEED)
    cells = generators.integer("cells", cells, 1, 10_000)
    tilt = generators.real("tilt", tilt, 0.0, 100.0)
    ripple = generators.real("ripple", ripple, 0.0, 100.0)
    ripple_frequency = generators.real("ripple_frequency", ripple_frequency, 0.0, 10_000.0)
    # Rings finer than the texels can hold would alias into a moiré. Fade them
    # out from a quarter to half the resolution (the Nyquist limit) instead, so
    # a low-resolution preview keeps the platelets and just loses the fine lines.
    ripple *= min(max(2.0 - 4.0 * ripple_frequency / resolution, 0.0), 1.0)

    rng = np.random.default_rng(seed)
    sites = rng.random((cells, 2))
    angle = rng.uniform(0.0, 2.0 * math.pi, cells)
    slope = tilt * np.sqrt(rng.random(cells))
    phase = rng.uniform(0.0, 2.0 * math.pi, cells)

    # Nearest site per texel. Squared distance on the torus separates into a
    # row term plus a column term, so each site costs one H × W add and compare.
    centres = (np.arange(resolution) + 0.5) / resolution
    nearest = np.full((resolution, resolution), np.inf)
    owner = np.zeros((resolution, resolution), dtype=np.intp)
    for k, (sx, sy) in enumerate(sites):
        d2 = _wrap(centres - sy)[:, None] ** 2 + _wrap(centres - sx)[None, :] ** 2
        closer = d2 < nearest
        nearest[closer] = d2[closer]
        owner[closer] = k

    dx = _wrap(centres[None, :] - sites[owner, 0])
    dy = _wrap(centres[:, None] - sites[owner, 1])
    d = np.sqrt(nearest)
    # Height ripple/(2πf) · sin(2πf d + φ): gradient is radial, of size ripple·cos(...).
    radial = ripple * np.cos(2.0 * math.pi * ripple_frequency * d + phase[owner])
    radial = np.divide(radial, d, out=np.zeros_like(d), where=d > 0.0)
    gx = (slope * np.cos(angle))[owner] + radial * dx
    gy = (slope * np.sin(angle))[owner] + radial * dy
    return _from_gradient(gx, gy)


def _decode(rgb: np.ndarray, full_scale: float) -> np.ndarray:
    """Texel values to unit normals; zero vectors stay zero.

    The shader treats a zero normal as "no map here" and keeps the geometric
    normal, so a zero must not be normalised into NaN.
    """
    n = 2.0 * np.asarray(rgb, dtype=np.float64) / full_scale - 1.0
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    unit: np.ndarray = np.divide(n, length, out=np.zeros_like(n), where=length > 0.0)
    return unit.astype(np.float32)


def from_image(path: str | os.PathLike[str]) -> np.ndarray:
    """A normal map from an RGB image file (anything Pillow opens).

    8-bit texels are quantised, so ``2c/255 - 1`` is only nearly unit length:
    renormalising keeps the shading exact for the direction that was stored.
    Black texels decode to ``(-1, -1, -1)/√3``, not to zero; only a true zero
    vector (impossible with 8-bit ``2c/255 - 1``) is kept as zero.
    """
    from PIL import Image  # only image files need Pillow: a cold render skips its import

    with Image.open(path) as image:
        rgb = np.asarray(image.convert("RGB"))
    return _decode(rgb, 255.0)


def _file(path: str | os.PathLike[str]) -> np.ndarray:
    """``from_image`` for requests: a path only, and unreadable files are a ``ValueError``."""
    if not isinstance(path, str | os.PathLike):
        raise ValueError(f"argument 'path' must be a file path, got {path!r}")
    try:
        return from_image(path)
    except OSError as error:  # includes FileNotFoundError and PIL.UnidentifiedImageError
        raise ValueError(f"argument 'path': cannot read {str(path)!r}: {error}") from None


def _none() -> None:
    return None


KINDS: dict[str, Callable[..., np.ndarray | None]] = {
    "none": _none,
    "bumps": bumps,
    "nacre": nacre,
    "file": _file,
}


def build(kind: str, **args: Any) -> np.ndarray | None:
    """Make a normal map from a name and keyword arguments, as requests spell them.

    ``"none"`` gives ``None`` (no map). Like ``geometry.build``, every failure
    is a ``ValueError`` naming the map kind and the argument.
    """
    return generators.call("normal map", KINDS, kind, args)
