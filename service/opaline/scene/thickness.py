"""Film-thickness fields, reproducible from a seed (KHR_materials_iridescence's
thickness texture): an ``(H, W)`` float32 array in [0, 1] that the shader maps to
[film_thickness_min, film_thickness_max] nm. Stored as images are (row 0 is the
top, v = 1), like the normal maps; the upload flips rows.

- ``swirl``: domain-warped fractal noise built from random Fourier modes on the
  torus (so it tiles): the marbled patches and streaks of oil on water.
- ``drain``: a soap film draining under gravity on a sphere's (u, v) map: thinnest
  at the top (v = 1), thickening downward, with horizontal swirls.
- ``platelets``: Voronoi cells, each its own thickness (nacre's aragonite tablets).
- ``file``: a greyscale image next to the preset.
- ``glb``: a user's .glb's own KHR thickness texture (``scene.gltf_film``).
- ``glb-factor``: its factor texture (KHR iridescenceTexture): the film's weight, not a
  thickness (a preset's ``weight_map``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from opaline.scene import generators

RESOLUTION = (8, 4096)
SEED = (0, 2**63 - 1)


def _grid(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    c = (np.arange(resolution) + 0.5) / resolution
    u, y = np.meshgrid(c, c)
    return u, 1.0 - y  # v = 1 on row 0


def _fourier_noise(rng: np.random.Generator, u: np.ndarray, v: np.ndarray, octaves: int,
                   base: int) -> np.ndarray:
    """Σ over octaves of random integer-frequency waves: tiles on the unit torus."""
    total = np.zeros_like(u)
    for octave in range(octaves):
        freq = base * 2**octave
        for _ in range(6):
            angle = rng.uniform(0.0, 2.0 * math.pi)
            kx = round(freq * math.cos(angle))
            ky = round(freq * math.sin(angle))
            phase = rng.uniform(0.0, 2.0 * math.pi)
            total += np.cos(2.0 * math.pi * (kx * u + ky * v) + phase) / 2**octave
    return total


def _normalise(x: np.ndarray) -> np.ndarray:
    lo, hi = float(x.min()), float(x.max())
    scaled: np.ndarray = (x - lo) / max(hi - lo, 1e-12)
    return scaled.astype(np.float32)


def swirl(
    resolution: int = 512, seed: int = 1, scale: int = 2, octaves: int = 4, warp: float = 0.35
) -> np.ndarray:
    """Marbled noise: fractal noise sampled at coordinates displaced by more noise."""
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    seed = generators.integer("seed", seed, *SEED)
    scale = generators.integer("scale", scale, 1, 32)
    octaves = generators.integer("octaves", octaves, 1, 8)
    warp = generators.real("warp", warp, 0.0, 2.0)
    rng = np.random.default_rng(seed)
    u, v = _grid(resolution)
    wu = _fourier_noise(rng, u, v, 3, scale)
    wv = _fourier_noise(rng, u, v, 3, scale)
    # Warp offsets are whole periods apart at the edges, so the field still tiles.
    field = _fourier_noise(rng, u + warp * wu / 4.0, v + warp * wv / 4.0, octaves, scale)
    return _normalise(field)


def drain(resolution: int = 512, seed: int = 1, power: float = 1.5, swirl: float = 0.12) -> np.ndarray:
    """(1 - v)^power with horizontal turbulence: a draining film on a sphere's uv map
    (v = 1 at the top pole), thinnest at the top, thickest at the bottom."""
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    seed = generators.integer("seed", seed, *SEED)
    power = generators.real("power", power, 0.1, 5.0)
    amount = generators.real("swirl", swirl, 0.0, 1.0)
    rng = np.random.default_rng(seed)
    u, v = _grid(resolution)
    # Displaced level lines: the horizontal bands of equal thickness wobble and curl.
    noise = _fourier_noise(rng, u, v, 3, 2)
    depth = np.clip(1.0 - v + amount * noise / 3.0 * np.sin(math.pi * v), 0.0, 1.0)
    return (depth**power).astype(np.float32)


def platelets(resolution: int = 512, seed: int = 1, cells: int = 90, spread: float = 1.0) -> np.ndarray:
    """Voronoi tablets on the torus, each with a uniform random value scaled by ``spread``."""
    resolution = generators.integer("resolution", resolution, *RESOLUTION)
    seed = generators.integer("seed", seed, *SEED)
    cells = generators.integer("cells", cells, 1, 4096)
    spread = generators.real("spread", spread, 0.0, 1.0)
    rng = np.random.default_rng(seed)
    sites = rng.random((cells, 2))
    value = 0.5 + spread * (rng.random(cells) - 0.5)
    centres = (np.arange(resolution) + 0.5) / resolution
    nearest = np.full((resolution, resolution), np.inf)
    owner = np.zeros((resolution, resolution), dtype=np.intp)
    for k, (sx, sy) in enumerate(sites):
        dy = (centres - sy + 0.5) % 1.0 - 0.5
        dx = (centres - sx + 0.5) % 1.0 - 0.5
        d2 = dy[:, None] ** 2 + dx[None, :] ** 2
        closer = d2 < nearest
        nearest[closer] = d2[closer]
        owner[closer] = k
    return value[owner].astype(np.float32)


def _file(path: str | os.PathLike[str]) -> np.ndarray:
    if not isinstance(path, str | os.PathLike):
        raise ValueError(f"argument 'path' must be a file path, got {path!r}")
    from PIL import Image  # only image files need Pillow: a cold render skips its import

    try:
        with Image.open(path) as image:
            grey = np.asarray(image.convert("F"), dtype=np.float32)
    except OSError as error:
        raise ValueError(f"argument 'path': cannot read {str(path)!r}: {error}") from None
    field: np.ndarray = np.clip(grey / 255.0, 0.0, 1.0)
    return field


def _glb_texture(path: str | os.PathLike[str], key: str) -> np.ndarray:
    from opaline.scene.gltf_film import IRIDESCENCE, read_film_textures

    try:
        with open(path, "rb") as stream:
            data = stream.read()
    except OSError as error:
        raise ValueError(f"argument 'path': cannot read {str(path)!r}: {error}") from None
    field = read_film_textures(data, (key,)).by_key().get(key)
    if field is None:
        raise ValueError(f"argument 'path': {str(path)!r} has no {IRIDESCENCE} {key}")
    return field


def _glb(path: str | os.PathLike[str], digest: str = "") -> np.ndarray:
    """The thickness texture of a user's .glb (``digest``: the file's, for the scene key)."""
    return _glb_texture(path, "iridescenceThicknessTexture")


def _glb_factor(path: str | os.PathLike[str], digest: str = "") -> np.ndarray:
    """The factor texture of a user's .glb: the film's weight per texel, times film_weight."""
    return _glb_texture(path, "iridescenceTexture")


KINDS: dict[str, Callable[..., np.ndarray]] = {
    "swirl": swirl,
    "drain": drain,
    "platelets": platelets,
    "file": _file,
    "glb": _glb,
    "glb-factor": _glb_factor,
}


def build(kind: str, **args: Any) -> np.ndarray:
    """A thickness field from a name and keyword arguments; failures are ValueErrors."""
    return generators.call("thickness field", KINDS, kind, args)
