"""Camera and key-light placement (opaline.model.camera): the override keeps distance and centre."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.camera import key_light_direction, place_key_light
from opaline.model.presets import Light

TARGET = (0.5, -0.25, 1.0)


@pytest.mark.parametrize("kind", ["point", "directional"])
@pytest.mark.parametrize(("azimuth", "elevation"), [(30.0, 45.0), (-120.0, -10.0), (None, 60.0),
                                                    (200.0, None)])
def test_moved_key_light_keeps_its_distance_and_reports_its_angles(kind, azimuth, elevation):
    """The first light moves to the angles asked (around the target for a point light, around
    the origin for a directional one) at its old distance; the others stay."""
    lights = [Light(type=kind, position=(2.0, 1.0, -0.5)), Light(type="point", position=(0, 3, 0))]
    before = key_light_direction(lights, TARGET)
    moved = place_key_light(lights, TARGET, azimuth, elevation)
    centre = np.asarray(TARGET) if kind == "point" else np.zeros(3)
    distance = np.linalg.norm(np.subtract(lights[0].position, centre))
    assert np.linalg.norm(np.subtract(moved[0].position, centre)) == pytest.approx(distance)
    after = key_light_direction(moved, TARGET)
    expected_az = before["azimuth"] if azimuth is None else (azimuth + 180.0) % 360.0 - 180.0
    assert after["azimuth"] == pytest.approx(expected_az, abs=1e-9)
    expected_el = before["elevation"] if elevation is None else elevation
    assert after["elevation"] == pytest.approx(expected_el, abs=1e-9)
    assert moved[1] == lights[1] and moved[0].type == kind


def test_no_override_leaves_the_lights_alone():
    """Without azimuth and elevation the very same list comes back."""
    lights = [Light(type="point", position=(1.0, 2.0, 3.0))]
    assert place_key_light(lights, TARGET, None, None) is lights
    assert key_light_direction([], TARGET) is None
