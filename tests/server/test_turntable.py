"""Turntables: 36 frames at 256² round-trip (frame count, size) in WebP, GIF and MP4; the
camera really turns; the CLI and HTTP paths work, report progress and respect the budget."""

from __future__ import annotations

import asyncio
import time

import numpy as np
import pytest
from fastapi.testclient import TestClient

from opaline.cli import main as cli
from opaline.local.turntable import turntable_bytes
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.model.turntable import TurntableRequest, frame_jobs
from opaline.output.animation import ANIMATION_FORMATS, decode, encode
from opaline.server.api import create_app
from opaline.server.service import Service
from opaline.server.turntable_jobs import failure_of, new_job
from opaline.server.turntable_runs import patiently
from opaline.settings import Settings
from opaline.workers.errors import DeadlineExceeded, Overloaded


def test_frames_step_once_around_from_the_still_view():
    request = TurntableRequest(preset="cd-rom", frames=8)
    preset = get_preset("cd-rom")
    jobs = frame_jobs(resolve(request.still(), preset), preset, 8)
    azimuths = np.array([j.camera_azimuth for j in jobs])
    assert azimuths[0] == pytest.approx(90.0)  # the preset's eye is on +z
    np.testing.assert_allclose(np.diff(np.unwrap(np.radians(azimuths))), np.radians(45.0))
    assert len({j.cache_key("s") for j in jobs}) == 8


@pytest.mark.parametrize("fmt", ANIMATION_FORMATS)
def test_encoders_round_trip_odd_sizes(fmt):
    frames = [np.full((30, 40, 3), 40 * i, np.uint8) for i in range(5)]
    assert decode(encode(frames, fmt, 10), fmt) == (5, (40, 30))


@pytest.mark.gl
@pytest.mark.parametrize("fmt", ANIMATION_FORMATS)
def test_36_frames_at_256_round_trip(local, fmt):
    request = TurntableRequest(preset="cd-rom", quality="draft", animation=fmt)
    seen: list[tuple[int, int]] = []
    data = turntable_bytes(local, request, progress=lambda done, total: seen.append((done, total)))
    assert decode(data, fmt) == (36, (256, 256))
    assert seen[-1] == (36, 36) and len(seen) == 36


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_cli_turntable(tmp_path, capsys):
    out = tmp_path / "turn.gif"
    code = cli.main(["turntable", "sphere", "--frames", "6", "--size", "64", "--quality",
                     "draft", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    from PIL import Image

    with Image.open(out) as image:
        frames = []
        for index in range(image.n_frames):
            image.seek(index)
            frames.append(np.asarray(image.convert("RGB"), dtype=np.float64))
    assert len(frames) == 6
    assert np.abs(frames[0] - frames[2]).mean() > 1.0  # the view changed


@pytest.mark.gl
def test_http_turntable_with_progress(backend):
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1,
                        cost_budget=64 * 64 * 1 * 8 * 8,  # 8 draft frames, 8 wavelengths
                        max_turntables=1)
    with TestClient(create_app(settings)) as client:
        over = client.post("/v1/turntables", json={"preset": "sphere", "frames": 9,
                                                   "width": 64, "height": 64, "quality": "draft"})
        assert over.status_code == 422 and "frames" in over.json()["detail"][0]
        # The turntable's own fields' ranges, as a render's are given (they said only
        # "less than or equal to 360", or nothing).
        for field, line in (({"frames": 361}, "frames=361 is out of range: allowed [2 … 360]"),
                            ({"fps": "x"}, "(allowed [1 … 60])")):
            bad = client.post("/v1/turntables", json={"preset": "sphere", **field})
            assert bad.status_code == 422 and line in bad.json()["detail"][0], bad.json()
        lax = client.post("/v1/turntables", json={"preset": "sphere", "light_elevation": False})
        assert lax.status_code == 422 and lax.json()["error"] == "invalid"  # strict, as render
        started = client.post("/v1/turntables", json={
            "preset": "sphere", "frames": 8, "width": 64, "height": 64, "quality": "draft",
            "animation": "webp"})
        assert started.status_code == 202, started.text
        status = started.json()
        assert started.headers["location"] == f"/v1/turntables/{status['id']}"
        deadline = time.monotonic() + 60
        progress = []
        while status["state"] == "running" and time.monotonic() < deadline:
            time.sleep(0.05)
            status = client.get(f"/v1/turntables/{status['id']}").json()
            progress.append(status["done"])
        assert status["state"] == "done", status
        assert progress == sorted(progress) and status["done"] == 8
        result = client.get(status["result"])
        assert result.status_code == 200 and result.headers["content-type"] == "image/webp"
        assert decode(result.content, "webp") == (8, (64, 64))
        # As every image answer: a strong ETag, 304 on it, Cache-Control, Server-Timing.
        assert result.headers["etag"].startswith('"') and "cache-control" in result.headers
        assert result.headers["server-timing"].startswith("hit")
        again = client.get(status["result"], headers={"If-None-Match": result.headers["etag"]})
        assert again.status_code == 304 and again.content == b""
        for path in ("/v1/turntables/nope", "/v1/turntables/nope/result"):
            unknown = client.get(path)
            assert unknown.status_code == 404 and unknown.json()["error"] == "unknown_turntable"
        # one running turntable is the cap here: another is 429 busy, the same one is not
        found = client.app.state.turntables
        x = {**new_job("x", "{}", 8, "webp"), "owner": found.owner, "lease_until": 1e12}
        found.store.put_record("turntable:x", x, 0, 60)
        found.running["x"] = (None, None)  # as if this replica were rendering it
        busy = client.post("/v1/turntables", json={"preset": "sphere", "frames": 2,
                                                   "width": 32, "height": 32})
        assert busy.status_code == 429 and busy.json()["error"] == "busy", busy.text
        assert " ".join(busy.json()["detail"]).count("retry later") == 1, busy.text
        assert int(busy.headers["retry-after"]) >= 1
        del found.running["x"]
        rendering = client.get("/v1/turntables/x/result")
        assert rendering.status_code == 409 and rendering.json()["error"] == "rendering"
        failure = failure_of(DeadlineExceeded("no image in 2 s"))
        found.store.put_record("turntable:x", {**x, "state": "failed", "failure": failure}, 1, 60)
        failed = client.get("/v1/turntables/x/result")
        assert failed.status_code == 503 and failed.json() == {
            "error": "deadline", "detail": ["no image in 2 s; retry later"]}
        assert int(failed.headers["retry-after"]) >= 1


class FullQueue:
    """A pool whose queue is full for the first ``refusals`` submissions."""

    def __init__(self, refusals: int) -> None:
        self.refusals, self.calls = refusals, 0

    async def render(self, key, task, timeout=None):
        self.calls += 1
        if self.calls <= self.refusals:
            raise Overloaded("full", retry_after_s=0.01)
        return b"frame"


def test_a_frame_waits_out_a_full_queue_until_the_turntable_deadline():
    svc = Service(Settings(), FullQueue(3), None, None, None, None)  # type: ignore[arg-type]

    async def go(deadline_in: float) -> bytes:
        return await patiently(svc, "k", None, asyncio.get_running_loop().time() + deadline_in)

    assert asyncio.run(go(5.0)) == b"frame" and svc.pool.calls == 4
    svc.pool.refusals, svc.pool.calls = 10**6, 0
    with pytest.raises(DeadlineExceeded, match="queue stayed full"):
        asyncio.run(go(0.05))
    assert svc.pool.calls > 1
