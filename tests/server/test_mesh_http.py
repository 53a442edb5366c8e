"""Meshes over HTTP: POST /v1/meshes stores by content hash (parsed only in a worker),
render requests name mesh=<id>, broken and over-limit files get 4xx, the service stays ready."""

from __future__ import annotations

import io

import numpy as np
import pytest
from fastapi.testclient import TestClient
from PIL import Image

from mesh_helpers import FORMATS, assert_framed, broken_files, mesh_bytes
from opaline.server.api import create_app
from opaline.server.meshstore import MeshStore, MeshTooLarge, UnknownMesh
from opaline.settings import Settings

SMALL = "width=96&height=80&quality=draft&transparent=true"


@pytest.fixture(scope="module")
def client(backend, tmp_path_factory):
    folder = tmp_path_factory.mktemp("meshes")
    (folder / "shelf.ply").write_bytes(mesh_bytes("ply"))
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                        mesh_max_bytes=400_000, mesh_max_triangles=5000, meshes_dir=folder,
                        mesh_store_dir=tmp_path_factory.mktemp("store"))
    with TestClient(create_app(settings)) as client:
        yield client


@pytest.mark.gl
def test_the_upload_names_its_summary_url(client):
    """The 201's Location answers the upload's summary; a mesh of the folder has one too,
    under its file name; an id never stored, or a name the folder lacks, is 404."""
    answer = client.post("/v1/meshes", content=mesh_bytes("obj"))
    assert answer.status_code == 201, answer.text
    assert answer.headers["location"] == f"/v1/meshes/{answer.json()['id']}"
    described = client.get(answer.headers["location"])
    assert described.status_code == 200 and described.json() == answer.json()
    shelf = client.get("/v1/meshes/shelf.ply")
    assert shelf.status_code == 200, shelf.text
    assert shelf.json()["id"] == "shelf.ply" and shelf.json()["format"] == "ply"
    for name in ("0" * 32, "nope.ply", ".hidden"):
        missing = client.get(f"/v1/meshes/{name}")
        assert missing.status_code == 404 and missing.json()["error"] == "unknown_mesh", name


@pytest.mark.gl
@pytest.mark.parametrize("fmt", FORMATS)
def test_upload_then_render_each_format(client, fmt):
    data = mesh_bytes(fmt)
    answer = client.post("/v1/meshes", content=data)
    assert answer.status_code == 201, answer.text
    info = answer.json()
    assert info["format"] == fmt and info["triangles"] == 2304 and len(info["id"]) == 32
    assert client.post("/v1/meshes", content=data).json()["id"] == info["id"]  # content hash
    image = client.get(f"/v1/render?preset=sphere&mesh={info['id']}&{SMALL}")
    assert image.status_code == 200, image.text
    rgba = np.asarray(Image.open(io.BytesIO(image.content)))
    assert rgba.shape == (80, 96, 4)
    assert_framed(rgba[..., 3] / 255.0)
    posted = client.post("/v1/render", json={"preset": "nacre", "mesh": info["id"],
                                             "camera_azimuth": 200, "width": 64, "height": 64})
    assert posted.status_code == 200 and posted.content.startswith(b"\x89PNG")


@pytest.mark.gl
def test_mesh_renders_are_timed_under_the_preset_they_name(client):
    """Each upload is a scene of its own (named by its digest); the render-time histogram
    labels it by the preset the request names, so uploads cannot grow the metrics. Before,
    every mesh rendered added a label (a series of buckets) of its own."""
    for fmt in FORMATS[:2]:
        info = client.post("/v1/meshes", content=mesh_bytes(fmt)).json()
        assert client.get(f"/v1/render?preset=nacre&mesh={info['id']}&{SMALL}"
                          "&camera_azimuth=33").status_code == 200
    text = client.get("/metrics").text
    labels = {line.split('preset="')[1].split('"')[0] for line in text.splitlines()
              if line.startswith("opaline_render_seconds_count{")}
    assert "nacre" in labels and not any(name.startswith("mesh-") for name in labels), labels


@pytest.mark.gl
def test_folder_meshes_by_name(client):
    assert client.get(f"/v1/render?mesh=shelf.ply&{SMALL}").status_code == 200
    # 300 characters: longer than any file name can be (ENAMETOOLONG was a 500).
    for name in ("../shelf.ply", "missing.ply", "0" * 32, "a" * 300):
        answer = client.get(f"/v1/render?mesh={name}&{SMALL}")
        assert answer.status_code == 404 and "POST /v1/meshes" in answer.json()["detail"][0]


@pytest.mark.gl
def test_a_mesh_refused_at_render_names_the_field(client):
    """tangent_field='uv' on an STL (no UVs) was a 422 whose `fields` was empty."""
    mesh_id = client.post("/v1/meshes", content=mesh_bytes("stl")).json()["id"]
    answer = client.get(f"/v1/render?mesh={mesh_id}&tangent_field=uv&{SMALL}")
    assert answer.status_code == 422, answer.text
    assert [p["field"] for p in answer.json()["fields"]] == ["tangent_field"]
    assert "no UV coordinates" in answer.json()["fields"][0]["message"]


@pytest.mark.gl
@pytest.mark.parametrize("name", sorted(broken_files()))
def test_broken_uploads_get_422_and_the_service_stays_ready(client, name):
    answer = client.post("/v1/meshes", content=broken_files()[name])
    assert answer.status_code == 422, answer.text
    assert answer.json()["error"] == "invalid_mesh" and len(answer.json()["detail"][0]) > 10
    assert client.get("/readyz").status_code == 200


@pytest.mark.gl
def test_over_limit_uploads(client):
    big = client.post("/v1/meshes", content=b"solid x\n" + b" " * 500_000)
    assert big.status_code == 413 and "400000" in big.json()["detail"][0]
    many = client.post("/v1/meshes", content=_many_triangles())
    assert many.status_code == 422 and "limit of 5000" in many.json()["detail"][0]
    empty = client.post("/v1/meshes", content=b"")
    assert empty.status_code == 422 and empty.json()["error"] == "invalid_mesh"
    assert client.get("/readyz").status_code == 200
    assert client.get(f"/v1/render?preset=sphere&{SMALL}").status_code == 200


@pytest.mark.gl
def test_a_reupload_whose_check_cannot_run_keeps_the_stored_copy(backend, tmp_path):
    """A mesh is the store's only once its check passed, and an upload whose check never ran
    (here refused at once: 422 too_slow under a tiny deadline) leaves the store as it was.
    Before, the refused re-upload discarded the copy already stored: its id answered 404."""
    data = mesh_bytes("ply")
    common = {"gl_backend": backend, "warmup": False, "calibrate": False, "workers": 1,
              "mesh_store_dir": tmp_path}
    with TestClient(create_app(Settings(**common))) as client:
        mesh_id = client.post("/v1/meshes", content=data).json()["id"]
        with TestClient(create_app(Settings(**common, deadline_s=0.05))) as hurried:
            refused = hurried.post("/v1/meshes", content=data)
            assert refused.status_code == 422 and refused.json()["error"] == "too_slow"
            assert refused.json()["detail"][0].startswith("checking this mesh file is")
            # A render's refusal names the fields the request set that drive its time.
            slow = hurried.get(f"/v1/render?preset=sphere&environment_samples=64&{SMALL}")
            assert slow.status_code == 422 and slow.json()["error"] == "too_slow"
            assert "lower environment_samples=64" in slow.json()["detail"][0]
            assert slow.json()["fields"][0]["field"] == "environment_samples"
        assert sorted(p.name for p in tmp_path.iterdir()) == [f"{mesh_id}.mesh"]
        image = client.get(f"/v1/render?preset=sphere&mesh={mesh_id}&{SMALL}")
        assert image.status_code == 200, image.text


def _many_triangles() -> bytes:
    import trimesh

    return trimesh.creation.icosphere(4).export(file_type="ply")  # 5120 triangles


def test_store_evicts_least_recently_used(tmp_path):
    settings = Settings(mesh_store_dir=tmp_path, mesh_store_bytes=2500, mesh_max_bytes=2000)
    store = MeshStore(settings)
    first, second = store.put(b"a" * 1000), store.put(b"b" * 1000)
    store.resolve(first)  # used: now the second is the oldest
    third = store.put(b"c" * 1000)
    assert store.evictions == 1 and store.size_bytes == 2000
    assert store.resolve(first)[0].read_bytes() == b"a" * 1000
    assert store.resolve(third)[1] == third
    with pytest.raises(UnknownMesh):
        store.resolve(second)
    with pytest.raises(MeshTooLarge):
        store.put(b"d" * 2001)
    reopened = MeshStore(settings)  # what is on disk survives a restart, in order
    assert sorted(reopened._sizes) == sorted([first, third])


def test_http_process_never_imports_a_mesh_parser():
    """The app and its routes load without trimesh: parsing is the workers' job."""
    import subprocess
    import sys

    code = ("import sys; sys.modules['trimesh'] = None\n"
            "from opaline.server.api import create_app\n"
            "from opaline.settings import Settings\n"
            "create_app(Settings(warmup=False, calibrate=False))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.mark.gl
def test_environment_over_http(client, tmp_path):
    """Names only: a path is refused, even to a map that exists (the CLI takes paths)."""
    cv2 = pytest.importorskip("cv2")
    on_disk = tmp_path / "room.hdr"
    assert cv2.imwrite(str(on_disk), np.ones((8, 16, 3), np.float32))
    lit = client.get(f"/v1/render?preset=sphere&environment=sky&environment_lights=8&{SMALL}")
    assert lit.status_code == 200 and lit.content.startswith(b"\x89PNG")
    for path in ("/v1/render", "/v1/export/glsl"):
        for name in ("../x.hdr", str(on_disk)):
            unknown = client.get(f"{path}?preset=sphere&environment={name}&{SMALL}")
            assert unknown.status_code == 404 and "not known" in unknown.json()["detail"][0]
            assert unknown.json()["error"] == "unknown_environment"
            assert "file's path" not in unknown.json()["detail"][0]  # nor offered one


@pytest.mark.gl
def test_exports_over_http(client):
    mesh_id = client.post("/v1/meshes", content=mesh_bytes("obj")).json()["id"]
    glsl = client.get("/v1/export/glsl?preset=cd-rom&mu_f=6")
    assert glsl.status_code == 200 and "opaline_radiance" in glsl.text
    assert "const real u_mu_f = 6.0;" in glsl.text
    glb = client.post("/v1/export/glb", json={"preset": "sphere", "mesh": mesh_id, "alpha": 3})
    assert glb.status_code == 200 and glb.content[:4] == b"glTF"
    from opaline.output.gltf import import_glb

    assert import_glb(glb.content)["alpha"] == 3.0
    assert client.post("/v1/export/glb", json={"mesh": "f" * 32}).status_code == 404
    # parsed strictly, as POST /v1/render's body: a boolean is not a number
    lax = client.post("/v1/export/glb", json={"preset": "sphere", "light_elevation": False})
    assert lax.status_code == 422 and lax.json()["error"] == "invalid"


def _peak_rss_mb(pid: int) -> float:
    """The process's peak resident set (VmHWM), in MB."""
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return 0.0


@pytest.mark.gl
def test_hostile_uploads_get_422_at_once_while_a_bystander_is_served(backend, tmp_path, capsys):
    """Issue 24's files, uploaded to a real server on loopback under the default limits: each
    422 naming its limit within 2 s, the check lane's worker never replaced and its peak RSS
    barely moved (before, the 316-byte GLB alone took a render worker to 4 GB); meanwhile
    another client polls /readyz and renders, and every one of its answers is 200 (checks
    have their own lane: before, a check priced at 10 s made its renders 503). The 16 KB GLB with two 8000² textures
    is a mesh: 201 at once, its images never decoded, drawn at once."""
    import threading
    import time

    import httpx

    from hostile_meshes import HOSTILE, glb_with_textures
    from opaline.server.localserver import LocalServer

    env = {"OPALINE_GL_BACKEND": backend, "OPALINE_WARMUP": "0", "OPALINE_CALIBRATE": "0",
           "OPALINE_MESH_STORE_DIR": str(tmp_path)}
    stop, ready, bystander = threading.Event(), [], []

    def bystand(base: str) -> None:
        with httpx.Client(base_url=base, trust_env=False, timeout=30) as other:
            while not stop.is_set():
                probe = other.get("/readyz")
                ready.append(probe.status_code if probe.status_code == 200 else probe.text)
                mu_f = 2 + len(bystander) / 64  # a new image each time: a render
                bystander.append(other.get(f"/v1/render?{SMALL}&mu_f={mu_f}").status_code)
                time.sleep(0.05)

    with (LocalServer(workers=1, env=env) as server,
          httpx.Client(base_url=server.base, trust_env=False, timeout=30) as client):
        pid = client.get("/readyz").json()["checks"][0]["pid"]  # the check lane's worker
        before = _peak_rss_mb(pid)
        watcher = threading.Thread(target=bystand, args=(server.base,))
        watcher.start()
        try:
            for name, (build, words) in sorted(HOSTILE.items()):
                body = build()
                start = time.monotonic()
                answer = client.post("/v1/meshes", content=body)
                seconds = time.monotonic() - start
                assert answer.status_code == 422, (name, answer.text)
                assert words in answer.json()["detail"][0] and seconds < 2.0, (name, seconds)
            start = time.monotonic()
            textured = client.post("/v1/meshes", content=glb_with_textures())
            assert textured.status_code == 201 and time.monotonic() - start < 2.0, textured.text
            start = time.monotonic()  # a render worker's first mesh: it imports trimesh
            drawn = client.get(f"/v1/render?mesh={textured.json()['id']}&{SMALL}")
            assert drawn.status_code == 200 and time.monotonic() - start < 5.0  # was 18-22 s
        finally:
            stop.set()
            watcher.join(30)
        assert client.get("/readyz").json()["checks"][0]["pid"] == pid  # never killed
        grown = _peak_rss_mb(pid) - before
    assert ready and set(ready) == {200}, ready
    assert bystander and set(bystander) == {200}, bystander
    assert sorted(p.name for p in tmp_path.iterdir()) == [textured.json()["id"] + ".mesh"]
    with capsys.disabled():
        print(f"\n  hostile uploads: {len(HOSTILE)} files refused, check worker peak RSS "
              f"{before:.0f} MB, +{grown:.0f} MB; bystander {len(bystander)} renders and "
              f"{len(ready)} /readyz, all 200")
    assert grown < 128
