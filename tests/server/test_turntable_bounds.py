"""Issue 24, item 4: turntables bounded. Finished animations are kept under a byte budget
(a forgotten one is rendered anew by its next POST), a running job's record is never
evicted by new ones (429 when only running ones are kept), and DELETE cancels."""

from __future__ import annotations

import time

import pytest
from fastapi.testclient import TestClient

from opaline.server.api import create_app
from opaline.server.statestore import KEPT, LocalState, StoreFull
from opaline.server.turntable_jobs import new_job
from opaline.settings import Settings

LONG = {"preset": "sphere", "frames": 360, "width": 32, "height": 32, "quality": "draft"}


def tiny(n: int) -> dict:
    return {"preset": "sphere", "frames": 2, "width": 64, "height": 64, "quality": "draft",
            "camera_azimuth": n}


def test_local_results_stay_under_their_byte_budget_the_newest_kept():
    state = LocalState(budget=10**9, bytes_budget=2500)
    for name in "abc":
        state.put(name, name.encode() * 1000, ttl_s=60)
    assert state.get("a") is None and state.get("b") and state.get("c")
    state.put("big", b"x" * 5000, ttl_s=60)  # alone over the budget: kept, the rest goes
    assert state.get("big") and state.get("b") is None and state.get("c") is None
    state.delete("big")
    state.put("d", b"d" * 2000, ttl_s=60)
    assert state.get("d")


def test_a_running_record_is_never_evicted():
    state = LocalState(budget=1000)
    state.put_record("running", {"state": "running"}, 0, 60)
    for n in range(2 * KEPT):
        state.put_record(f"done-{n}", {"state": "done"}, 0, 60)
    assert state.record("running") is not None  # the finished ones made room instead
    for n in range(KEPT - 1):
        state.put_record(f"busy-{n}", {"state": "running"}, 0, 60)
    with pytest.raises(StoreFull):  # every one kept is running: refused, none evicted
        state.put_record("one-more", {"state": "running"}, 0, 60)
    assert state.record("running") is not None and state.record("busy-0") is not None


def wait_for(client: TestClient, turntable_id: str, state: str, within_s: float = 60) -> dict:
    end = time.monotonic() + within_s
    while True:
        status = client.get(f"/v1/turntables/{turntable_id}").json()
        if status["state"] == state or time.monotonic() > end:
            assert status["state"] == state, status
            return status
        time.sleep(0.05)


@pytest.mark.gl
def test_running_turntables_survive_new_ones_and_delete_cancels(backend):
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                        max_turntables=2, turntable_result_bytes=1024)
    with TestClient(create_app(settings)) as client:
        found = client.app.state.turntables
        long = client.post("/v1/turntables", json=LONG).json()
        assert long["state"] == "running"
        for n in range(KEPT + 6):  # as if 70 tiny turntables had finished meanwhile
            done = {**new_job(f"t{n}", "{}", 2, "webp"), "state": "done"}
            found.store.put_record(f"turntable:t{n}", done, 0, 60)
        assert client.get(f"/v1/turntables/{long['id']}").json()["state"] == "running"
        assert long["id"] in found.running
        # tiny ones beside it: the second's animation pushes the first's out of the budget
        first = client.post("/v1/turntables", json=tiny(1)).json()
        wait_for(client, first["id"], "done")
        assert client.get(first["result"]).status_code == 200
        second = client.post("/v1/turntables", json=tiny(2)).json()
        wait_for(client, second["id"], "done")
        forgotten = client.get(first["result"])
        assert forgotten.status_code == 404 and "forgotten" in forgotten.json()["detail"][0]
        again = client.post("/v1/turntables", json=tiny(1))  # rendered anew
        assert again.status_code == 202 and again.json()["state"] == "running"
        wait_for(client, first["id"], "done")
        # DELETE: 202 cancelled, the job stops, reads answer 404 cancelled; POST starts it anew
        gone = client.delete(f"/v1/turntables/{long['id']}")
        assert gone.status_code == 202 and gone.json()["state"] == "cancelled", gone.text
        assert long["id"] not in found.running
        done = gone.json()["done"]
        time.sleep(0.5)
        record = found.store.record(f"turntable:{long['id']}")
        assert record is not None and record.value["done"] == done  # it rendered no more
        for url in (f"/v1/turntables/{long['id']}", long["result"]):
            answer = client.get(url)
            assert answer.status_code == 404 and answer.json()["error"] == "cancelled", url
        assert client.delete("/v1/turntables/nope").status_code == 404
        restarted = client.post("/v1/turntables", json=LONG)
        assert restarted.status_code == 202 and restarted.json()["state"] == "running"
        assert client.delete(f"/v1/turntables/{long['id']}").status_code == 202
        # only running records kept: a new turntable is refused, none is evicted
        for n in range(KEPT):
            busy = {**new_job(f"r{n}", "{}", 2, "webp"), "lease_until": 1e12, "owner": "x"}
            found.store.put_record(f"turntable:r{n}", busy, 0, 60)
        full = client.post("/v1/turntables", json=tiny(3))
        assert full.status_code == 429 and full.json()["error"] == "busy", full.text
        assert "retry-after" in full.headers


def test_an_encode_is_priced_by_its_frames_size_and_format():
    import io

    from PIL import Image

    from opaline.output.animation import encode_cost_s
    from opaline.workers.animation_task import AnimationTask

    png = io.BytesIO()
    Image.new("RGB", (64, 32)).save(png, format="PNG")
    task = AnimationTask((png.getvalue(),) * 10, "mp4", 24)
    assert task.units()[3] == encode_cost_s(10, 64, 32, "mp4") > 0  # counted as work ahead
    assert encode_cost_s(360, 860, 860, "mp4") > 10 * encode_cost_s(36, 256, 256, "mp4")


@pytest.mark.gl
def test_the_largest_legal_turntable_is_refused_at_once_if_its_encode_cannot_finish(backend):
    """360 frames at 860² used to render every frame, then die in the encode at the 30 s
    watchdog on every retry; its encode is now priced at admission."""
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1)
    largest = {"preset": "sphere", "frames": 360, "width": 860, "height": 860,
               "quality": "draft", "wavelengths": 0}  # 798,768,000 of the 805,306,368 budget
    with TestClient(create_app(settings)) as client:
        for fmt in ("mp4", "webp"):
            started = time.monotonic()
            answer = client.post("/v1/turntables", json={**largest, "animation": fmt})
            assert answer.status_code == 422 and answer.json()["error"] == "too_slow", answer.text
            assert "encoding the 360 frames" in answer.json()["detail"][0]
            assert time.monotonic() - started < 2.0
        small = client.post("/v1/turntables", json={**tiny(0), "animation": "mp4"})
        assert small.status_code == 202, small.text
        wait_for(client, small.json()["id"], "done")
