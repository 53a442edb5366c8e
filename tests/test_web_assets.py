"""The tuning page's assets in a real headless Chromium: drop a mesh, choose an environment,
orbit, and download the image, a turntable and the exports."""

from __future__ import annotations

import pytest

from mesh_helpers import mesh_bytes
from opaline.output.animation import decode
from test_web import (  # noqa: F401
    CHROMIUM,
    browser,
    open_page,
    page,
    server,
    settle,
    shown_bytes,
    wait_until,
)

pytestmark = pytest.mark.skipif(not CHROMIUM.exists(), reason=f"{CHROMIUM} is missing")


def test_mesh_upload_environment_orbit_and_downloads(page, tmp_path):  # noqa: F811
    open_page(page)
    sphere = shown_bytes(page)
    path = tmp_path / "torus.glb"
    path.write_bytes(mesh_bytes("glb"))
    page.set_input_files("#mesh-file", str(path))
    wait_until(page, "() => document.querySelector('#mesh-status').textContent"
                     ".includes('triangles')")
    settle(page)
    assert "2304 triangles" in page.text_content("#mesh-status")
    torus = shown_bytes(page)
    assert torus != sphere and "mesh=" in page.get_attribute("#preview", "data-url")

    page.select_option("#env-pick", "sky")
    settle(page)
    lit = shown_bytes(page)
    assert lit != torus and "environment=sky" in page.get_attribute("#preview", "data-url")
    page.fill("#in-camera_azimuth", "200")
    page.press("#in-camera_azimuth", "Enter")
    settle(page)
    assert shown_bytes(page) != lit

    with page.expect_download() as image:
        page.click("#dl-image")
    assert open(image.value.path(), "rb").read()[:4] == b"\x89PNG"
    with page.expect_download() as glsl:
        page.click("#dl-glsl")
    assert "opaline_radiance" in open(glsl.value.path()).read()
    with page.expect_download() as glb:
        page.click("#dl-glb")
    assert open(glb.value.path(), "rb").read()[:4] == b"glTF"
    page.fill("#tt-frames", "4")
    page.select_option("#tt-format", "gif")
    with page.expect_download(timeout=60_000) as turntable:
        page.click("#dl-turntable")
    data = open(turntable.value.path(), "rb").read()
    assert decode(data, "gif")[0] == 4
