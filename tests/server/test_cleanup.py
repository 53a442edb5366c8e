"""Issue 24, item 7: no mesh folder or temporary file outlives ``opaline serve``, however it
stops: SIGTERM and SIGINT (uvicorn re-raises them, so only the lifespan's shutdown runs),
SIGKILL (the next start-up sweeps what it left), and an MP4 encode killed mid-file.

Each server gets its own TMPDIR, so what is counted is its leftovers only.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import httpx
import pytest

from mesh_helpers import mesh_bytes
from opaline.server.localserver import LocalServer, ServerError, loopback_env


def serve(tmp: Path) -> LocalServer:
    env = {"OPALINE_WARMUP": "false", "OPALINE_CALIBRATE": "false", "TMPDIR": str(tmp)}
    try:
        return LocalServer(workers=1, env=env).__enter__()
    except ServerError as exc:
        pytest.fail(str(exc))


def leftovers(tmp: Path) -> list[Path]:
    return sorted(p for p in tmp.iterdir() if p.name.startswith(("opaline-", "tmp")))


def upload(server: LocalServer, tmp: Path) -> Path:
    """Store a mesh; the store's folder, which now holds it."""
    answer = httpx.post(server.base + "/v1/meshes", content=mesh_bytes("ply"), timeout=60)
    assert answer.status_code == 201, answer.text
    (folder,) = [p for p in leftovers(tmp) if p.is_dir()]
    assert (folder / f"{answer.json()['id']}.mesh").is_file()
    return folder


def wait_exit(proc: subprocess.Popen, what: str) -> None:
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail(f"{what} did not exit in 30 s")


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_leaves_nothing(tmp_path, signum):
    server = serve(tmp_path)
    with server:
        upload(server, tmp_path)
        server.proc.send_signal(signum)
        wait_exit(server.proc, "opaline serve")
    assert leftovers(tmp_path) == []


def test_the_next_start_sweeps_what_sigkill_left(tmp_path):
    server = serve(tmp_path)
    with server:
        killed = upload(server, tmp_path)
        server.proc.kill()
        wait_exit(server.proc, "opaline serve")
    assert killed.is_dir()  # SIGKILL runs no cleanup
    again = serve(tmp_path)
    with again:
        assert not killed.exists()  # its owner is gone: swept at start-up
        live = upload(again, tmp_path)
        assert leftovers(tmp_path) == [live]
        again.proc.send_signal(signal.SIGTERM)
        wait_exit(again.proc, "opaline serve")
    assert leftovers(tmp_path) == []


ENCODE = """
import numpy as np
from opaline.output.animation import encode
rng = np.random.default_rng(1)
frames = [rng.integers(0, 256, (480, 640, 3), dtype=np.uint8) for _ in range(40)]
encode(frames * 20, "mp4", 24)
"""


def ffmpeg_writing(tmp: Path) -> bool:
    """Whether an ffmpeg still has a file of ``tmp`` on its command line."""
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if str(tmp).encode() in cmdline.read_bytes():
                return True
        except OSError:
            continue
    return False


def test_a_killed_mp4_encode_is_swept_at_start_up(tmp_path):
    encoder = subprocess.Popen([sys.executable, "-c", ENCODE],
                               env=loopback_env(TMPDIR=str(tmp_path)))
    end = time.monotonic() + 60
    while not list(tmp_path.glob("*.mp4")) and time.monotonic() < end:
        assert encoder.poll() is None, "the encoder exited before making its file"
        time.sleep(0.05)
    assert list(tmp_path.glob("*.mp4")), "no MP4 was being encoded within 60 s"
    time.sleep(0.5)  # ffmpeg started and writing
    os.kill(encoder.pid, signal.SIGKILL)
    encoder.wait(10)
    while ffmpeg_writing(tmp_path) and time.monotonic() < end:  # ffmpeg ends at the EOF
        time.sleep(0.1)
    (left,) = list(tmp_path.glob("*.mp4"))  # what a killed encode leaves
    server = serve(tmp_path)
    with server:
        assert not left.exists()
