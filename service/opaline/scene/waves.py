"""A sum-of-sines heightfield: the liquid surface under the oil-slick presets."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from opaline.scene import generators
from opaline.scene.mesh import Mesh, grid_indices, make_mesh

TWO_PI = 2.0 * math.pi
RESOLUTION = (2, 2048)

# Gentle, mutually oblique swells: at most ~0.35 of slope together, so an oil
# slick's thin-film colours shift across the surface without it looking stormy.
# (amplitude, wavelength, direction in degrees, phase in radians)
DEFAULT_WAVES: tuple[tuple[float, float, float, float], ...] = (
    (0.030, 2.10, 15.0, 0.0),
    (0.018, 1.30, 70.0, 1.3),
    (0.010, 0.73, 135.0, 2.1),
    (0.005, 0.41, 205.0, 0.7),
)


def check_waves(waves: object) -> np.ndarray:
    """(K, 4) float64 rows of amplitude, wavelength, direction (deg), phase."""
    if isinstance(waves, str | bytes) or not isinstance(waves, Sequence | np.ndarray):
        raise ValueError(f"argument 'waves' must be a list of 4-tuples, got {waves!r}")
    rows = []
    for k, wave in enumerate(waves):
        wave = generators.sequence(f"waves[{k}]", wave, 4)
        amplitude, wavelength, direction, phase = (generators.real(f"waves[{k}]", v) for v in wave)
        if wavelength <= 0.0:
            raise ValueError(f"argument 'waves[{k}]' needs a wavelength > 0, got {wavelength}")
        rows.append((amplitude, wavelength, direction, phase))
    return np.array(rows, dtype=np.float64).reshape(-1, 4)


def wave_height(
    x: npt.ArrayLike, z: npt.ArrayLike, waves: object = DEFAULT_WAVES
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height and its gradient ``(h, dh/dx, dh/dz)`` of the wavy surface.

    Public so that tests and other code (e.g. a reference ray caster) can use
    the same surface the mesh samples, in float64.
    """
    w = check_waves(waves)
    x = np.asarray(x, dtype=np.float64)[..., None]
    z = np.asarray(z, dtype=np.float64)[..., None]
    amplitude, wavelength, direction, phase = w.T
    k = TWO_PI / wavelength
    dx, dz = np.cos(np.radians(direction)), np.sin(np.radians(direction))
    arg = k * (x * dx + z * dz) + phase
    slope = amplitude * k * np.cos(arg)
    return (
        (amplitude * np.sin(arg)).sum(-1),
        (slope * dx).sum(-1),
        (slope * dz).sum(-1),
    )


def wavy_surface(
    size: float = 4.0,
    resolution: int = 192,
    waves: Sequence[tuple[float, float, float, float]] = DEFAULT_WAVES,
) -> Mesh:
    """Sum-of-sines heightfield, a liquid surface for an oil-slick material.

    ``resolution`` is the number of vertices along each side. Normals come from
    the analytic gradient rather than from the triangles, so the shading stays
    smooth at any resolution; the tangent is dP/dx, which keeps the anisotropy
    aligned with x as the surface rolls. ``u`` follows +x and ``v`` follows -z
    (the top face of a box seen from above), so ``cross(n, t)`` is along +v.
    """
    size = generators.positive("size", size)
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    rows = check_waves(waves)

    s = np.linspace(-0.5 * size, 0.5 * size, resolution)
    zz, xx = np.meshgrid(s, s, indexing="ij")  # row i = z, column j = x
    x, z = xx.ravel(), zz.ravel()
    h, hx, hz = wave_height(x, z, rows)

    positions = np.stack([x, h, z], 1)
    normals = np.stack([-hx, np.ones_like(x), -hz], 1)
    tangents = np.stack([np.ones_like(x), hx, np.zeros_like(x)], 1)
    uvs = np.stack([x / size + 0.5, 0.5 - z / size], 1)
    # Grid (b-a)×(c-a) = x × z = -y, so swap b and c to face +y.
    indices = grid_indices(resolution, resolution)[:, [0, 2, 1]]
    return make_mesh(positions, normals, tangents, uvs, indices)
