"""Camera and light placement: view-projection matrices and the key-light override.

The matrices are row-vector (``v @ M``) as pyrr wrote them, formula for formula: their
bytes are the GL column-major matrices. A few NumPy lines instead of pyrr, whose import
was 5 ms of every cold ``opaline render``."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from opaline.model.meshes import MESH_VIEW
from opaline.model.presets import Camera, Light, Vec3


def perspective(fov_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """gluPerspective, row-vector."""
    top = near * np.tan(fov_deg * np.pi / 360.0)
    right = top * aspect
    return np.array([[2.0 * near / (2.0 * right), 0.0, 0.0, 0.0],
                     [0.0, 2.0 * near / (2.0 * top), 0.0, 0.0],
                     [0.0, 0.0, -(far + near) / (far - near), -1.0],
                     [0.0, 0.0, -2.0 * far * near / (far - near), 0.0]])


def _unit(v: np.ndarray) -> np.ndarray:
    unit: np.ndarray = v / np.sqrt(np.sum(v**2))
    return unit


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    """gluLookAt, row-vector."""
    forward = _unit(target - eye)
    side = _unit(np.cross(forward, up))
    up = _unit(np.cross(side, forward))
    return np.array([[side[0], up[0], -forward[0], 0.0],
                     [side[1], up[1], -forward[1], 0.0],
                     [side[2], up[2], -forward[2], 0.0],
                     [-np.dot(side, eye), -np.dot(up, eye), np.dot(forward, eye), 1.0]])


def view_projection(camera: Camera, aspect: float) -> np.ndarray:
    """Row-vector view·projection; its bytes are the GL column-major matrix."""
    eye = np.asarray(camera.eye, dtype=np.float64)
    target = np.asarray(camera.target, dtype=np.float64)
    distance = float(np.linalg.norm(eye - target))
    near, far = max(distance * 0.02, 1e-3), distance * 10.0
    projection = perspective(camera.fov_deg, aspect, near, far)
    view = look_at(eye, target, np.asarray(camera.up, dtype=np.float64))
    view_proj: np.ndarray = view @ projection
    return view_proj


def _rotation(theta: float, axis: int) -> np.ndarray:
    """Rotation by ``theta`` about x (0), y (1) or z (2), as pyrr's ``from_*_rotation``."""
    c, s = np.cos(theta), np.sin(theta)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(4)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def model_matrix(rotation_deg: tuple[float, float, float]) -> np.ndarray:
    rx, ry, rz = (math.radians(a) for a in rotation_deg)
    model: np.ndarray = _rotation(rx, 0) @ _rotation(ry, 1) @ _rotation(rz, 2)
    return model


def _centre(light: Light, target: Vec3) -> np.ndarray | float:
    """What a light's position is taken around: the target for a point light; a directional
    light's "position" is already a direction, so the origin."""
    return np.asarray(target, dtype=np.float64) if light.type == "point" else 0.0


def _key_offset(light: Light, target: Vec3) -> np.ndarray:
    return np.asarray(light.position, dtype=np.float64) - _centre(light, target)


def key_light_direction(lights: list[Light], target: Vec3) -> dict[str, float] | None:
    """Where the first light sits, in the degrees light_azimuth/light_elevation use."""
    return _direction(lights[0], target) if lights else None


def _direction(light: Light, target: Vec3) -> dict[str, float]:
    offset = _key_offset(light, target)
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
    current = _direction(key, target)
    az = math.radians(current["azimuth"] if azimuth_deg is None else azimuth_deg)
    el = math.radians(current["elevation"] if elevation_deg is None else elevation_deg)
    direction = np.array([math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)])
    position = direction * radius + _centre(key, target)
    moved = key.model_copy(update={"position": tuple(float(x) for x in position)})
    return [moved, *lights[1:]]


# Orbit and framing. Angles as the key light's: azimuth atan2(z, x), elevation above y = 0.
FRAME_MARGIN = 1.08  # the bounding sphere fills the shorter side of the image, with a margin


def orbit(target: npt.ArrayLike, azimuth_deg: float, elevation_deg: float, distance: float
          ) -> tuple[float, ...]:
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    direction = np.array([math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)])
    return tuple(float(x) for x in np.asarray(target, dtype=np.float64) + direction * distance)


def framing_distance(radius: float, fov_deg: float, aspect: float) -> float:
    """The distance at which a sphere of ``radius`` fits the narrower field of view."""
    half_v = math.radians(fov_deg) / 2.0
    half = min(half_v, math.atan(math.tan(half_v) * aspect))
    return FRAME_MARGIN * radius / math.sin(half)


def fit_matrix(sphere: tuple[npt.ArrayLike, float], target: Vec3) -> np.ndarray:
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
