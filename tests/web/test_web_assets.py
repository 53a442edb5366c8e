"""The tuning page's assets in a real headless Chromium: drop a mesh, choose an environment,
orbit, and download the image, a turntable and the exports."""

from __future__ import annotations

import pytest

from mesh_helpers import mesh_bytes
from opaline.output.animation import decode
from opaline.server.localserver import LocalServer, ServerError
from test_web import (  # noqa: F401
    CHROMIUM,
    START_S,
    WAIT_MS,
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

    # A user's mesh is lit by the sky already (its default): the studio changes the picture.
    page.select_option("#env-pick", "studio")
    settle(page)
    lit = shown_bytes(page)
    assert lit != torus and "environment=studio" in page.get_attribute("#preview", "data-url")
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


def test_assets_with_an_api_key_answer_2xx(browser, tmp_path):  # noqa: F811
    """With keys (and signing) on, the key typed into the page goes with every request it
    makes: the mesh upload, the turntable and its polls, the exports all answer 2xx."""
    key = "assets-key-41c9"
    env = {"OPALINE_API_KEYS": key, "OPALINE_SIGNING_KEY": "assets-secret-8f02"}
    answers: list[tuple[int, str]] = []
    try:
        with LocalServer(workers=1, env=env, ready_path="/healthz", start_timeout_s=START_S) as local:
            context = browser.new_context()
            context.set_default_timeout(WAIT_MS)
            page = context.new_page()
            page.on("response", lambda r: answers.append((r.status, r.request.method + " " + r.url))
                    if "/v1/" in r.url else None)
            page.goto(local.base + "/")
            page.wait_for_selector("#key-form:not([hidden])")
            page.fill("#api-key", key)
            page.click("#key-form button")
            settle(page)
            answers.clear()  # the 403s that asked for the key
            path = tmp_path / "torus.glb"
            path.write_bytes(mesh_bytes("glb"))
            page.set_input_files("#mesh-file", str(path))
            wait_until(page, "() => /triangles|:/.test("
                             "document.querySelector('#mesh-status').textContent)")
            assert "2304 triangles" in page.text_content("#mesh-status")
            settle(page)
            for button in ("#dl-image", "#dl-glb"):
                with page.expect_download() as download:
                    page.click(button)
                assert download.value.failure() is None
            page.fill("#tt-frames", "3")
            page.select_option("#tt-format", "gif")
            with page.expect_download(timeout=60_000) as turntable:
                page.click("#dl-turntable")
            assert decode(open(turntable.value.path(), "rb").read(), "gif")[0] == 3
            context.close()
    except ServerError as exc:
        pytest.fail(str(exc))
    asked = {url.split("?")[0].rsplit("/v1/", 1)[1].split("/")[0] for _, url in answers}
    assert {"meshes", "turntables", "export", "render"} <= asked, answers
    assert all(200 <= status < 300 for status, _ in answers), answers
