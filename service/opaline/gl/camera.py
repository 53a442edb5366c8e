"""Camera and light placement: view-projection matrices (pyrr) and the key-light override."""

from __future__ import annotations

import math

import numpy as np
from pyrr import Matrix44

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
