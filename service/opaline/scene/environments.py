"""Environments that light a scene: procedural (a studio, a sky) and HDR image files.

Each is an equirectangular map of linear radiance (``mediancut`` gives the
convention), turned into directional lights by ``mediancut.median_cut``. The
procedural ones are made here, in closed form, at a fixed size, so they cost
nothing to ship and are the same on every machine:

* ``studio``: a grey room with soft-box panels, the key above and in front, as
  product shots use; ``neutral``: a soft grey gradient (both in ``scene.studio``);
* ``sky``: a clear sky (brighter at the horizon, deeper blue at the zenith),
  a sun 35° up, and a dim ground.

Files (Radiance ``.hdr``, OpenEXR ``.exr``) are read from the environments folder of
the settings (and, in the CLI, the Python API and local batches, from any path), in
the worker processes, by ``environment_files``: bounded before they
are decoded, cleaned (a photographed or rendered map with a few broken pixels still
lights a scene, and nothing it holds can reach a pixel as NaN or Inf), fitted to the
sizes lighting uses, and known by their content. ``map_identity`` is what a cache of
maps is keyed by: a file replaced under its name is read again.
"""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path

import numpy as np

from opaline.scene.environment_files import EnvironmentMapError, fit, read_file
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


def check_name(name: str, folder: Path | None, paths: bool = False) -> Path | None:
    """The file ``name`` means (None for a built-in one), without reading it: the HTTP
    process checks names, workers read files. ``paths``: this machine's own tools (CLI,
    Python, local batches) also take a path to an .hdr/.exr file, after the folder's
    names; the service never does, so no client can name a file outside the folder."""
    if name in BUILTIN or name == NO_ENVIRONMENT:
        return None
    if folder is not None and Path(name).name == name and name.lower().endswith(SUFFIXES):
        path = Path(folder) / name
        if path.is_file():
            return path
    if paths and name.lower().endswith(SUFFIXES):
        path = expand_user(Path(name))
        if path.is_file():
            return path.absolute()
        if Path(name).name != name:  # meant as a path: say so, as a missing mesh does
            raise EnvironmentMapError(f"environment={name!r}: no such file")
    # A path is not a name: a file is named as it is in the folder (which the message
    # names by its setting: the CLI user whose path was refused has to know where it goes).
    where = ("the environments folder (OPALINE_ENVIRONMENTS_DIR)" if folder is not None
             else "an environments folder, and OPALINE_ENVIRONMENTS_DIR names none here")
    files = f"an .hdr/.exr file's path or the name of one in {where}" if paths else \
        f"the name of an .hdr/.exr file of {where}"
    raise EnvironmentMapError(f"environment={name!r} is not known: choose studio, neutral, "
                              f"sky, none, or {files}")


def expand_user(path: Path) -> Path:
    """``~`` and ``~user`` expanded where they name a home; as written where not (an
    unknown user raised RuntimeError, past every caller's handling of a bad name)."""
    try:
        return path.expanduser()
    except RuntimeError:
        return path


def map_identity(name: str, folder: Path | None, paths: bool = False) -> tuple[object, ...]:
    """What a cache of maps is keyed by: the name, and for a file its path, size and time."""
    path = check_name(name, folder, paths)
    if path is None:
        return (name,)
    stat = path.stat()
    return (name, str(path), stat.st_size, stat.st_mtime_ns)


def resolve_map(name: str, folder: Path | None, paths: bool = False) -> np.ndarray:
    path = check_name(name, folder, paths)
    if path is not None:
        return fit(read_file(path))
    if name == "studio":
        return studio()
    return neutral() if name == "neutral" else sky()


# (map_identity, count) -> (directions, irradiances)
_lights: OrderedDict[tuple[object, ...], tuple[np.ndarray, np.ndarray]] = OrderedDict()


def environment_lights(name: str, count: int, rotation_deg: float = 0.0, intensity: float = 1.0,
                       folder: Path | None = None,
                       paths: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(K, 3) directions toward the lights and (K, 3) irradiances, rotated about +y by
    ``rotation_deg`` (the environment turns, the object stays) and scaled by ``intensity``."""
    key = (*map_identity(name, folder, paths), count)
    if key not in _lights:
        _lights[key] = median_cut(resolve_map(name, folder, paths), count)
        while len(_lights) > CACHED:
            _lights.popitem(last=False)
    _lights.move_to_end(key)
    direction, irradiance = _lights[key]
    a = np.radians(rotation_deg)
    # Azimuth grows from +x toward +z (atan2(z, x)): rotate by +a in that sense.
    rotate = np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])
    return direction @ rotate, irradiance * intensity
