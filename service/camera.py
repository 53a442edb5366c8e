"""Camera and light placement: view-projection matrices (pyrr) and the key-light override."""

from __future__ import annotations

import math

import numpy as np
from pyrr import Matrix44

from .presets import Camera, Light


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
    centre = np.asarray(target, dtype=np.float64)
    offset = np.asarray(key.position, dtype=np.float64) - (centre if key.type == "point" else 0.0)
    radius = float(np.linalg.norm(offset)) or 1.0
    current_az = math.degrees(math.atan2(offset[2], offset[0]))
    current_el = math.degrees(math.asin(max(-1.0, min(1.0, offset[1] / radius))))
    az = math.radians(current_az if azimuth_deg is None else azimuth_deg)
    el = math.radians(current_el if elevation_deg is None else elevation_deg)
    direction = np.array([math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)])
    position = direction * radius + (centre if key.type == "point" else 0.0)
    moved = key.model_copy(update={"position": tuple(float(x) for x in position)})
    return [moved, *lights[1:]]
