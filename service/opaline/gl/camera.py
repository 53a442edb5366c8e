"""Camera and light placement: view-projection matrices (pyrr) and the key-light override."""

from __future__ import annotations

import math

import numpy as np
from pyrr import Matrix44

from opaline.model.meshes import MESH_VIEW
from opaline.model.presets import Camera, Light


def view_projection(camera: Camera, aspect: float) -> np.ndarray:
    """Row-vector (pyrr) view·projection; its bytes are the GL column-major matrix."""
    eye = np.asarray(camera.eye, dtype=np.float64)
    target = np.asarray(camera.target, dtype=np.float64)
    distance = float(np.linalg.norm(eye - target))
    near, far = max(distance * 0.02, 1e-3), distance * 10.0
    projection = Matrix44.perspective_projection(camera.fov_deg, aspect, near, far, dtype="f8")
    view = Matrix44.look_at(eye, target, np.asarray(camera.up, dtype=np.float64), dtype="f8")
    return np.asarray(view) @ np.asarray(projection)


def model_matrix(rotation_deg: tuple[float, float, float]) -> np.ndarray:
    rx, ry, rz = (math.radians(a) for a in rotation_deg)
    rotation = (
        Matrix44.from_x_rotation(rx, dtype="f8")
        @ Matrix44.from_y_rotation(ry, dtype="f8")
        @ Matrix44.from_z_rotation(rz, dtype="f8")
    )
    return np.asarray(rotation)


def _centre(light: Light, target) -> np.ndarray | float:
    """What a light's position is taken around: the target for a point light; a directional
    light's "position" is already a direction, so the origin."""
    return np.asarray(target, dtype=np.float64) if light.type == "point" else 0.0


def _key_offset(light: Light, target) -> np.ndarray:
    return np.asarray(light.position, dtype=np.float64) - _centre(light, target)


def key_light_direction(lights: list[Light], target) -> dict[str, float] | None:
    """Where the first light sits, in the degrees light_azimuth/light_elevation use."""
    if not lights:
        return None
    offset = _key_offset(lights[0], target)
    radius = float(np.linalg.norm(offset)) or 1.0
    return {
        "azimuth": math.degrees(math.atan2(offset[2], offset[0])),
        "elevation": math.degrees(math.asin(max(-1.0, min(1.0, offset[1] / radius)))),
    }


def place_key_light(
    lights: list[Light],
    target: tuple[float, float, float],
    azimuth_deg: float | None,
    elevation_deg: float | None,
) -> list[Light]:
    """Move the first light to an azimuth/elevation around the target, keeping its distance."""
    if azimuth_deg is None and elevation_deg is None:
        return lights
    key = lights[0]
    offset = _key_offset(key, target)
    radius = float(np.linalg.norm(offset)) or 1.0
    current = key_light_direction(lights, target)
    az = math.radians(current["azimuth"] if azimuth_deg is None else azimuth_deg)
    el = math.radians(current["elevation"] if elevation_deg is None else elevation_deg)
    direction = np.array([math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)])
    position = direction * radius + _centre(key, target)
    moved = key.model_copy(update={"position": tuple(float(x) for x in position)})
    return [moved, *lights[1:]]


# Orbit and framing. Angles as the key light's: azimuth atan2(z, x), elevation above y = 0.
FRAME_MARGIN = 1.08  # the bounding sphere fills the shorter side of the image, with a margin


def orbit(target, azimuth_deg: float, elevation_deg: float, distance: float) -> tuple:
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    direction = np.array([math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)])
    return tuple(float(x) for x in np.asarray(target, dtype=np.float64) + direction * distance)


def framing_distance(radius: float, fov_deg: float, aspect: float) -> float:
    """The distance at which a sphere of ``radius`` fits the narrower field of view."""
    half_v = math.radians(fov_deg) / 2.0
    half = min(half_v, math.atan(math.tan(half_v) * aspect))
    return FRAME_MARGIN * radius / math.sin(half)


def fit_matrix(sphere: tuple, target) -> np.ndarray:
    """Row-vector model matrix that moves a mesh's bounding sphere (centre, radius) onto a
    unit sphere at ``target``: a user's mesh then sits where the preset's lights and camera
    expect an object, whatever units it was modelled in (mm, m, or a 1e4-wide scan)."""
    centre, radius = np.asarray(sphere[0], dtype=np.float64), max(float(sphere[1]), 1e-30)
    fit = np.eye(4)
    fit[:3, :3] /= radius
    fit[3, :3] = np.asarray(target, dtype=np.float64) - centre / radius
    return fit


def view_camera(camera: Camera, aspect: float, framed: bool = False,
                azimuth_deg: float | None = None, elevation_deg: float | None = None,
                distance: float | None = None) -> Camera:
    """The camera a job sees through: ``framed`` (a user's mesh, fitted to a unit sphere at
    the target by ``fit_matrix``) looks at that sphere from ``MESH_VIEW`` at the distance
    that fits it in the image; then the orbit fields move it. ``distance`` is a multiple of
    the framed or preset distance."""
    target = np.asarray(camera.target, dtype=np.float64)
    offset = np.asarray(camera.eye, dtype=np.float64) - target
    radius = float(np.linalg.norm(offset)) or 1.0
    az = math.degrees(math.atan2(offset[2], offset[0]))
    el = math.degrees(math.asin(max(-1.0, min(1.0, offset[1] / radius))))
    if framed:
        radius = framing_distance(1.0, camera.fov_deg, aspect)
        az, el = MESH_VIEW
    elif azimuth_deg is None and elevation_deg is None and distance is None:
        return camera
    az = az if azimuth_deg is None else azimuth_deg
    el = max(-89.0, min(89.0, el if elevation_deg is None else elevation_deg))
    eye = orbit(target, az, el, radius * (distance or 1.0))
    return camera.model_copy(update={"eye": eye, "up": (0.0, 1.0, 0.0)})
