"""The service on a real Redis (OPALINE_STATE_URL) that goes down and comes back: uploads
and turntables answer 503 store_unavailable with Retry-After, plain renders (and meshes
this replica already holds) keep working, and everything recovers with the store."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from mesh_helpers import mesh_bytes
from opaline.server.api import create_app
from opaline.settings import Settings
from redis_helpers import LocalRedis

SMALL = "width=48&height=48&quality=draft"
TURNTABLE = {"preset": "sphere", "frames": 2, "width": 32, "height": 32, "quality": "draft"}


@pytest.mark.gl
def test_the_store_down_is_503_for_state_only_and_recovers(backend, tmp_path):
    with LocalRedis() as redis:
        settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                            state_url=redis.url, state_timeout_s=0.5, mesh_store_dir=tmp_path)
        with TestClient(create_app(settings)) as client:
            mesh_id = client.post("/v1/meshes", content=mesh_bytes("stl")).json()["id"]
            started = client.post("/v1/turntables", json=TURNTABLE)
            assert started.status_code == 202, started.text
            redis.stop()
            for answer in (client.post("/v1/meshes", content=mesh_bytes("ply")),
                           client.post("/v1/turntables", json={**TURNTABLE, "frames": 3}),
                           client.get(f"/v1/turntables/{started.json()['id']}"),
                           client.get(f"/v1/turntables/{started.json()['id']}/result")):
                assert answer.status_code == 503, answer.text
                assert answer.json()["error"] == "store_unavailable"
                assert answer.json()["detail"][0].startswith(
                    f"the state store {redis.url} did not answer ")
                assert answer.json()["detail"][0].endswith("; retry later")
                assert int(answer.headers["retry-after"]) >= 1
            assert client.get(f"/v1/render?preset=cd-rom&{SMALL}").status_code == 200
            assert client.get(f"/v1/render?mesh={mesh_id}&{SMALL}").status_code == 200
            redis.start()  # empty: this one keeps nothing on disk
            again = client.post("/v1/meshes", content=mesh_bytes("ply"))
            assert again.status_code == 201, again.text
            assert client.post("/v1/turntables", json=TURNTABLE).status_code == 202
