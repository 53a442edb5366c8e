"""Environment lighting: median cut keeps the map's energy at every K, the environment turns
with its rotation, and a render converges as K rises (error falls monotonically)."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.params import RenderRequest
from opaline.scene import environment_files, environments
from opaline.scene.mediancut import directions, median_cut

COUNTS = (1, 4, 16, 64)
REFERENCE = 256


@pytest.mark.parametrize("name", environments.BUILTIN)
def test_median_cut_keeps_the_total_and_finds_the_bright_part(name):
    radiance = environments.resolve_map(name, None)
    d, solid = directions(*radiance.shape[:2])
    total = (radiance * solid[..., None]).sum((0, 1))
    for count in (1, 7, 32):
        toward, irradiance = median_cut(radiance, count)
        assert len(toward) == count
        np.testing.assert_allclose(np.linalg.norm(toward, axis=1), 1.0)
        np.testing.assert_allclose(irradiance.sum(0), total, rtol=1e-9)
    # One light sits at the energy's centroid: for the sky, near the sun (35° up).
    toward, _ = median_cut(radiance, 1)
    if name == "sky":
        assert np.degrees(np.arcsin(toward[0, 1])) == pytest.approx(35.0, abs=6.0)
    solid_total = solid.sum() * radiance.shape[1]
    assert solid_total == pytest.approx(4 * np.pi, rel=1e-3)


def test_a_black_map_is_one_light_of_nothing():
    """Not zero lights: the surface program cannot be compiled with LIGHT_COUNT 0."""
    toward, irradiance = median_cut(np.zeros((16, 32, 3)), 8)
    assert toward.shape == irradiance.shape == (1, 3)
    assert np.all(irradiance == 0.0) and np.linalg.norm(toward) == pytest.approx(1.0)


def test_rotation_turns_the_lights_about_up():
    base, e0 = environments.environment_lights("sky", 4)
    turned, e1 = environments.environment_lights("sky", 4, rotation_deg=90.0, intensity=2.0)
    azimuth = np.degrees(np.arctan2(base[:, 2], base[:, 0]))
    turned_azimuth = np.degrees(np.arctan2(turned[:, 2], turned[:, 0]))
    np.testing.assert_allclose((turned_azimuth - azimuth) % 360.0, 90.0, atol=1e-6)
    np.testing.assert_allclose(turned[:, 1], base[:, 1])
    np.testing.assert_allclose(e1, 2.0 * e0)


def test_unknown_environment_is_refused():
    with pytest.raises(ValueError, match="not known"):
        environments.environment_lights("../etc/passwd", 4)


@pytest.mark.gl
@pytest.mark.parametrize("name", environments.BUILTIN)
def test_render_converges_as_k_rises(local, name):
    """RMS error against K=256 falls monotonically with K, and K=64 is close."""
    def render(count: int) -> np.ndarray:
        request = RenderRequest(preset="sphere", environment=name, environment_lights=count,
                                width=64, height=64, samples=1, wavelengths=0, aa="none")
        return local.render_array(request)[..., :3].astype(np.float64)

    reference = render(REFERENCE)
    errors = [float(np.sqrt(np.mean((render(k) - reference) ** 2))) for k in COUNTS]
    assert all(a > b for a, b in zip(errors, errors[1:], strict=False)), errors
    assert errors[-1] < 0.25 * errors[0], errors


@pytest.mark.parametrize("suffix", [".hdr", ".exr"])
def test_hdr_files_from_the_environments_folder(tmp_path, suffix):
    """A Radiance .hdr (OpenCV) and an OpenEXR file (OpenEXR) of the sky light like the sky."""
    sky = environments.sky()
    path = tmp_path / f"sky{suffix}"
    if suffix == ".hdr":
        cv2 = pytest.importorskip("cv2")
        cv2.imwrite(str(path), np.ascontiguousarray(sky[..., ::-1]))
    else:
        exr = pytest.importorskip("OpenEXR")
        header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage}
        with exr.File(header, {"RGB": sky}) as file:
            file.write(str(path))
    _, from_file = environments.environment_lights(path.name, 8, folder=tmp_path)
    _, builtin = environments.environment_lights("sky", 8)
    np.testing.assert_allclose(from_file.sum(0), builtin.sum(0), rtol=0.01)  # RGBE: 1% steps
    (tmp_path / f"bad{suffix}").write_bytes(b"#?RADIANCE\nnot really")
    with pytest.raises(environments.EnvironmentMapError, match="cannot read"):
        environments.environment_lights(f"bad{suffix}", 8, folder=tmp_path)


def test_files_that_cannot_be_read_are_refused_by_name_without_the_folder(tmp_path):
    """A Radiance header declaring 2M × 2M texels (OpenCV raised its own error, which ended
    the worker: a 500 and a restart per request), an EXR without R, G and B, an empty EXR:
    each an EnvironmentMapError that names the file and not the server's folder."""
    exr = pytest.importorskip("OpenEXR")
    pytest.importorskip("cv2")
    (tmp_path / "huge.hdr").write_bytes(
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2000000 +X 2000000\n")
    header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage}
    with exr.File(header, {"Y": np.ones((4, 8), dtype=np.float32)}) as file:
        file.write(str(tmp_path / "grey.exr"))
    (tmp_path / "empty.exr").write_bytes(b"")
    for name, why in (("huge.hdr", "scale it down"), ("grey.exr", "no R, G and B channels"),
                      ("empty.exr", "cannot read")):
        with pytest.raises(environments.EnvironmentMapError) as caught:
            environment_files.read_file(tmp_path / name)
        message = str(caught.value)
        assert message.startswith(f"environment {name}: ") and why in message, message
        assert str(tmp_path) not in message


@pytest.mark.gl
def test_background_shows_the_environment(local):
    """With environment_background the pixels around the object are the map's radiance
    (here: a view up into the sky is blue, brighter toward the horizon), else the preset's."""
    common = dict(preset="sphere", environment="sky", width=48, height=48, samples=1,
                  wavelengths=0, aa="none", camera_elevation=-30.0)
    shown = local.render_array(RenderRequest(environment_background=True, **common))
    plain = local.render_array(RenderRequest(**common))
    assert shown[..., 3].min() == pytest.approx(1.0)  # every pixel covered
    assert plain[0, 0, 3] == 0.0  # the corners are the preset's background
    corner = shown[0, 0, :3]
    assert corner[2] > corner[0] and corner[2] > 0.05  # sky blue above
    sky = environments.sky()
    assert corner[2] <= sky[..., 2].max()


BACKDROP = dict(preset="sphere", environment="studio", environment_background=True,
                width=64, height=64, samples=1, wavelengths=0, aa="none", camera_distance=10.0,
                camera_azimuth=180.0)  # far off, so the sphere is a dot; looking at the seam (+x)


def _backdrop(local, **fields):
    image = local.render_array(RenderRequest(**{**BACKDROP, **fields}))[..., :3]
    image = image.astype(np.float64)
    image[28:36, 28:36] = np.nan  # the sphere
    return image


@pytest.mark.gl
def test_blur_zero_is_the_sharp_backdrop(local):
    """Blur 0 draws what no blur draws, bit for bit, and keeps the panels' edges."""
    sharp = local.render_array(RenderRequest(**BACKDROP))
    zero = local.render_array(RenderRequest(**BACKDROP, environment_blur=0.0))
    np.testing.assert_array_equal(zero, sharp)
    slight = local.render_array(RenderRequest(**BACKDROP, environment_blur=0.2))
    assert not np.array_equal(slight, sharp)


def _high_frequency(image):
    laplacian = (4 * image[1:-1, 1:-1] - image[:-2, 1:-1] - image[2:, 1:-1]
                 - image[1:-1, :-2] - image[1:-1, 2:])
    return float(np.nanmean(np.abs(laplacian)))


@pytest.mark.gl
def test_blur_one_is_smooth_and_keeps_the_mean(local):
    """Full blur: the backdrop's high-frequency energy falls to a small part of the sharp
    one's (panels and the floor's edge washed out), its mean stays, and the blur grows
    with the field (the seam across the view stays invisible: no jump between columns)."""
    sharp, half, full = (_backdrop(local, environment_blur=b) for b in (0.0, 0.5, 1.0))
    assert _high_frequency(full) < 0.15 * _high_frequency(sharp)
    assert _high_frequency(full) < _high_frequency(half) < _high_frequency(sharp)
    assert np.nanmean(full) == pytest.approx(np.nanmean(sharp), rel=0.15)
    columns = np.abs(np.diff(np.nanmean(full, axis=(0, 2))))
    assert columns.max() < 4 * np.median(columns) + 1e-3


@pytest.mark.gl
def test_backdrop_leaves_the_object_alone(local):
    """The map behind the object is bound to a texture unit of its own: a preset with a
    thickness map (nacre-film) draws the same object with and without the backdrop (the
    map once shared the thickness map's unit, so the film read the sky as its thickness)."""
    common = dict(preset="nacre-film", environment="sky", width=48, height=48, samples=1,
                  wavelengths=0, aa="none")
    shown = local.render_array(RenderRequest(environment_background=True, **common))
    plain = local.render_array(RenderRequest(**common))
    covered = plain[..., 3] == 1.0
    assert covered.sum() > 300
    np.testing.assert_array_equal(shown[covered, :3], plain[covered, :3])


def test_a_users_broken_texels_are_sanitised_and_logged(tmp_path, caplog):
    """NaN, ±Inf and negatives read as 0, radiance above MAX_RADIANCE as the maximum,
    the rest as written; the worker's log says how many were changed."""
    from environment_cases import ENVIRONMENT_MAPS, write_environment

    pytest.importorskip("OpenEXR")
    written = ENVIRONMENT_MAPS["nan-inf"][1]()
    with caplog.at_level("WARNING", logger="opaline.scene.environment_files"):
        radiance = environment_files.read_file(tmp_path / write_environment(tmp_path, "nan-inf"))
    broken = ~np.isfinite(written) | (written < 0)
    assert np.all(radiance[broken] == 0.0)
    huge = ~broken & (written > environment_files.MAX_RADIANCE)
    assert huge.any() and np.all(radiance[huge] == environment_files.MAX_RADIANCE)
    rest = ~broken & ~huge
    assert np.array_equal(radiance[rest], written[rest])
    assert f"{int(broken.sum())} non-finite or negative values set to 0" in caplog.text
    assert f"{int(huge.sum())} above 1e+10 clamped" in caplog.text


def test_a_clean_file_reads_unchanged_and_silently(tmp_path, caplog):
    from environment_cases import ENVIRONMENT_MAPS, write_environment

    pytest.importorskip("OpenEXR")
    with caplog.at_level("WARNING", logger="opaline.scene.environment_files"):
        radiance = environment_files.read_file(tmp_path / write_environment(tmp_path, "range-1e5"))
    assert np.array_equal(radiance, ENVIRONMENT_MAPS["range-1e5"][1]())
    assert caplog.text == ""
