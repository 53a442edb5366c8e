"""A user's environment file (scene/environment_files.py): bounded before it is decoded,
fitted to the sizes lighting uses, read in the layouts tools write, refused when it is
not what its name says, and known by its content."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest

from opaline.local.context import local_context
from opaline.model import irradiance
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare
from opaline.scene import environment_files, environments

cv2 = pytest.importorskip("cv2")
OpenEXR = pytest.importorskip("OpenEXR")


def write_hdr(path, radiance: np.ndarray) -> None:
    assert cv2.imwrite(str(path), np.ascontiguousarray(radiance[..., ::-1], dtype=np.float32))


def write_exr(path, channels: dict[str, np.ndarray]) -> None:
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as file:
        file.write(str(path))


def test_a_map_over_the_limit_is_refused_before_it_is_decoded(tmp_path, monkeypatch):
    """The header's size decides: 16384 × 8192 declared (1.6 GB decoded) is refused in no
    time, naming the size and the limit, without the rest of the file being read; an
    EXR's data window likewise (the limit lowered here, not to write 400 MB)."""
    (tmp_path / "big.hdr").write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
                                       b"-Y 8192 +X 16384\n")
    write_exr(tmp_path / "big.exr", {"RGB": np.zeros((2, 4000, 3), np.float32)})
    with pytest.raises(environment_files.EnvironmentMapError):
        environment_files.read_file(tmp_path / "big.hdr")
    monkeypatch.setattr(environment_files, "MAX_FILE_PIXELS", 7999)
    for name, size in (("big.hdr", "16384 × 8192"), ("big.exr", "4000 × 2")):
        with pytest.raises(environment_files.EnvironmentMapError) as caught:
            environment_files.read_file(tmp_path / name)
        message = str(caught.value)
        assert message.startswith(f"environment {name}: ") and size in message, message
        assert "8192 × 4096" in message and "scale it down" in message


def test_a_multi_part_exr_is_refused_before_any_part_is_decoded(tmp_path, monkeypatch):
    """Only the first part's window was checked, and every part was decoded: a 16384²
    second part behind a 64 × 32 first one (600 KB of file) cost a worker 530 MB."""
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              "displayWindow": ((0, 0), (99, 99))}
    parts = [OpenEXR.Part(dict(header), {"RGB": np.ones((32, 64, 3), np.float32)}, name="small"),
             OpenEXR.Part(dict(header), {"Y": np.zeros((100, 100), np.float16)}, name="more")]
    with OpenEXR.File(parts) as file:
        file.write(str(tmp_path / "parts.exr"))
    with pytest.raises(environment_files.EnvironmentMapError, match="2 parts"):
        environment_files.read_file(tmp_path / "parts.exr")


@pytest.mark.parametrize("shape", [(1, 1), (1, 2), (2, 4), (2, 512), (64, 128), (128, 256),
                                   (1100, 2300), (3000, 100), (4, 20000)])
def test_a_uniform_map_lights_alike_at_any_size(tmp_path, shape):
    """Before, a 1 × 1 map's constant term was 4.93 where π is right and a 512 × 2 one had
    0.98 in its second band: a handful of rows, each taken at its centre's solid angle;
    and a map over GL's 16384 texels wide lit nothing (its texture was never made)."""
    write_hdr(tmp_path / "flat.hdr", np.full((*shape, 3), 0.5, np.float32))
    radiance = environments.resolve_map("flat.hdr", tmp_path)
    height, width = radiance.shape[:2]
    assert 128 <= width <= 2048 and 64 <= height <= 1024
    reference = irradiance.coefficients(np.full((128, 256, 3), 0.5, np.float32))
    np.testing.assert_allclose(irradiance.coefficients(radiance), reference, atol=2e-3)


def test_fitting_keeps_what_each_direction_sees():
    """Repeated up, each direction keeps its texel's radiance; averaged down, a bright
    patch keeps its energy, where it was."""
    small = np.arange(2 * 4 * 3, dtype=np.float32).reshape(2, 4, 3)
    grown = environment_files.fit(small)
    assert grown.shape == (64, 128, 3)
    np.testing.assert_array_equal(grown[::32, ::32], small)
    big = np.zeros((2048, 4096, 3), np.float32)
    big[100:140, 3000:3040] = 10.0
    shrunk = environment_files.fit(big)
    assert shrunk.shape == (1024, 2048, 3)
    np.testing.assert_allclose(shrunk.sum() * 4, big.sum(), rtol=1e-4)
    rows, columns = np.nonzero(shrunk[..., 0] > 0)
    assert (rows.min(), rows.max(), columns.min(), columns.max()) == (50, 69, 1500, 1519)


def test_an_rgba_exr_is_read_and_a_png_named_hdr_is_refused(tmp_path):
    """RGBA is what most tools write (its alpha is not light); a PNG renamed .hdr was read
    by OpenCV as radiance 0-255, a white blown-out scene."""
    sky = environments.sky()
    alpha = np.ones((*sky.shape[:2], 1), np.float32)
    write_exr(tmp_path / "rgba.exr", {"RGBA": np.concatenate([sky, alpha], -1)})
    np.testing.assert_array_equal(environment_files.read_file(tmp_path / "rgba.exr"), sky)
    assert cv2.imwrite(str(tmp_path / "photo.png"), np.full((8, 16, 3), 200, np.uint8))
    os.replace(tmp_path / "photo.png", tmp_path / "photo.hdr")
    with pytest.raises(environment_files.EnvironmentMapError, match="not a Radiance .hdr"):
        environment_files.read_file(tmp_path / "photo.hdr")


def test_a_file_replaced_under_its_name_is_a_new_scene(tmp_path):
    """The key (and the canonical URL's rev) follows the file's content, and the lights
    made from it are made again: before, the first file's lights and images were answered
    until the process restarted."""
    path = tmp_path / "swap.hdr"
    write_hdr(path, np.full((32, 64, 3), 0.2, np.float32))
    context = replace(local_context(cost_budget=None), environments_dir=tmp_path)
    request = RenderRequest(preset="sphere", environment="swap.hdr")
    first = prepare(request, context)
    _, grey = environments.environment_lights("swap.hdr", 4, folder=tmp_path)
    assert prepare(request, context).key == first.key  # the same bytes, the same key
    write_hdr(path, np.stack([np.full((32, 64), v, np.float32) for v in (0.0, 0.1, 0.9)], -1))
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    second = prepare(request, context)
    assert second.key != first.key and second.url() != first.url()
    _, blue = environments.environment_lights("swap.hdr", 4, folder=tmp_path)
    assert grey.sum(0)[2] < blue.sum(0)[2] and blue.sum(0)[0] == 0.0
    builtin = prepare(RenderRequest(preset="sphere", environment="studio"), context)
    assert "+" not in builtin.scene_key  # a built-in's key is the preset's, as before
