"""Environments that light a scene: procedural (a studio, a sky) and HDR image files.

Each is an equirectangular map of linear radiance (``mediancut`` gives the
convention), turned into directional lights by ``mediancut.median_cut``. The
procedural ones are made here, in closed form, at a fixed size, so they cost
nothing to ship and are the same on every machine:

* ``studio``: a grey room with soft-box panels, the key above and in front, as
  product shots use; ``neutral``: a soft grey gradient (both in ``scene.studio``);
* ``sky``: a clear sky (brighter at the horizon, deeper blue at the zenith),
  a sun 35° up, and a dim ground.

Files (Radiance ``.hdr`` through OpenCV's reader, OpenEXR ``.exr`` through
the OpenEXR package) are read from
the environments folder of the settings, in the worker processes; both
libraries are imported only when a file is asked for. A file's NaN, infinite and
negative texels become 0 and its radiance is clamped to ``MAX_RADIANCE`` (logged):
a photographed or rendered map with a few broken pixels still lights a scene, and
nothing it holds can reach a pixel as NaN or Inf.
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from pathlib import Path

import numpy as np

from opaline.scene.mediancut import directions, median_cut
from opaline.scene.studio import neutral, studio

BUILTIN = ("studio", "neutral", "sky")
# Names no map: the preset's own lights (what a user's mesh, lit by the sky by default,
# asks for to get them back).
NO_ENVIRONMENT = "none"
# A user's mesh is lit by this unless the request names another (or none): on scanned
# meshes the presets' lights, placed for their own geometry, miss it. Mean CIELAB chroma
# over the Stanford bunny, 10 presets (docs/gallery): sky highest on 8, at 3.4-33.
MESH_ENVIRONMENT = "sky"
SIZE = (128, 256)  # rows, columns: 1.4° per texel, enough for the sun's disc
SUFFIXES = (".hdr", ".exr")
CACHED = 8
# The most radiance a file's texel keeps. Far above any real scene in relative units (a
# sun is ~1e5 times its sky); below it every range at its end (environment_intensity
# 1000, ks 100, the three-lobe mixture's weight 3, exposure 1000: 3e8 per unit radiance)
# keeps fp32 finite through the ACES tone map, whose x² overflows above 1.8e19.
MAX_RADIANCE = 1e10

log = logging.getLogger(__name__)


class EnvironmentMapError(ValueError):
    """An environment that is not known or cannot be read; the message says which."""


def sky() -> np.ndarray:
    d, _ = directions(*SIZE)
    e = np.clip(d[..., 1:2], 0.0, 1.0)
    zenith, horizon = np.array([0.04, 0.09, 0.22]), np.array([0.22, 0.26, 0.32])
    blue = horizon + (zenith - horizon) * np.sqrt(e)
    ground = np.array([0.04, 0.035, 0.03])
    radiance = np.where(d[..., 1:2] > 0, blue, ground)
    sun_dir = np.array([np.cos(np.radians(35)) * np.cos(0.9), np.sin(np.radians(35)),
                        np.cos(np.radians(35)) * np.sin(0.9)])
    # A disc 2.5° across (wider than the real 0.53°, so 1.4° texels resolve it) carrying
    # about three times the sky's irradiance, as on a clear day.
    sun = (d @ sun_dir > np.cos(np.radians(1.25)))[..., None]
    lit: np.ndarray = radiance + sun * np.array([1.0, 0.95, 0.88]) * 2400.0
    return lit.astype(np.float32)


def read_file(path: Path) -> np.ndarray:
    """Linear RGB float32 (H, W, 3) from a Radiance .hdr or an OpenEXR file."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".exr":
            import OpenEXR

            with OpenEXR.File(str(path)) as exr:
                channels = exr.channels()
                if "RGB" in channels:
                    image = np.asarray(channels["RGB"].pixels, dtype=np.float32)
                elif all(c in channels for c in "RGB"):
                    image = np.stack([np.asarray(channels[c].pixels, dtype=np.float32)
                                      for c in "RGB"], -1)
                else:
                    raise ValueError(f"no R, G and B channels (it has {', '.join(channels)})")
        else:
            image = _read_radiance(path)
    except ImportError as exc:
        raise EnvironmentMapError(f"environment {path.name}: reading {suffix} files needs "
                                  f"{exc.name}, a dependency of opaline: reinstall it") from None
    except (OSError, ValueError, KeyError, RuntimeError) as exc:
        # The folder is the server's business: the message names the file, not its path.
        reason = str(exc).replace(str(path), path.name)
        raise EnvironmentMapError(f"environment {path.name}: cannot read: {reason}") from None
    if image.ndim != 3 or image.shape[2] < 3:
        raise EnvironmentMapError(f"environment {path.name}: expected finite RGB, got "
                                f"shape {image.shape}")
    return sanitised(path.name, image[..., :3])


def _read_radiance(path: Path) -> np.ndarray:
    import cv2  # opencv-python-headless: reads Radiance RGBE as float32 BGR

    try:
        decoded = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except cv2.error as exc:  # e.g. a header declaring more pixels than OpenCV allows
        raise ValueError(f"OpenCV refused it: {exc.err} ({exc.func})") from None
    if decoded is None:
        raise ValueError("not a Radiance .hdr image")
    image: np.ndarray = np.asarray(decoded, dtype=np.float32)[..., 2::-1]
    return image


def sanitised(name: str, radiance: np.ndarray) -> np.ndarray:
    """NaN, ±Inf and negative texels as 0 (a broken pixel is no light: an Inf taken as the
    maximum would put a sun where none is), the rest clamped to ``MAX_RADIANCE``."""
    broken = ~np.isfinite(radiance) | (radiance < 0.0)
    bright = ~broken & (radiance > MAX_RADIANCE)
    if broken.any() or bright.any():
        log.warning("environment %s: %d non-finite or negative values set to 0, %d above "
                    "%g clamped", name, int(broken.sum()), int(bright.sum()), MAX_RADIANCE)
    clean: np.ndarray = np.where(broken, 0.0, np.minimum(radiance, MAX_RADIANCE))
    return clean.astype(np.float32)


def check_name(name: str, folder: Path | None) -> Path | None:
    """The file ``name`` means (None for a built-in one), without reading it: the HTTP
    process checks names, workers read files."""
    if name in BUILTIN or name == NO_ENVIRONMENT:
        return None
    if folder is not None and Path(name).name == name and name.lower().endswith(SUFFIXES):
        path = Path(folder) / name
        if path.is_file():
            return path
    raise EnvironmentMapError(f"environment={name!r} is not known: choose studio, neutral, "
                            "sky, none, or an .hdr/.exr file of the environments folder")


def resolve_map(name: str, folder: Path | None) -> np.ndarray:
    path = check_name(name, folder)
    if path is not None:
        return read_file(path)
    if name == "studio":
        return studio()
    return neutral() if name == "neutral" else sky()


# (name, count, folder) -> (directions, irradiances)
_lights: OrderedDict[tuple[str, int, str], tuple[np.ndarray, np.ndarray]] = OrderedDict()


def environment_lights(name: str, count: int, rotation_deg: float = 0.0, intensity: float = 1.0,
                       folder: Path | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(K, 3) directions toward the lights and (K, 3) irradiances, rotated about +y by
    ``rotation_deg`` (the environment turns, the object stays) and scaled by ``intensity``."""
    key = (name, count, str(folder))
    if key not in _lights:
        _lights[key] = median_cut(resolve_map(name, folder), count)
        while len(_lights) > CACHED:
            _lights.popitem(last=False)
    _lights.move_to_end(key)
    direction, irradiance = _lights[key]
    a = np.radians(rotation_deg)
    # Azimuth grows from +x toward +z (atan2(z, x)): rotate by +a in that sense.
    rotate = np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])
    return direction @ rotate, irradiance * intensity
