"""opaline.scratch: a sweep removes what dead owners left, never what a live one holds."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from opaline import scratch
from opaline.server.localserver import loopback_env


def test_sweep_spares_the_living_and_removes_the_dead(tmp_path, monkeypatch):
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr("tempfile.tempdir", None)  # re-read TMPDIR
    fd, mine = scratch.owned_file("encode", ".mp4")
    lock, folder = scratch.owned_dir("meshes")
    assert scratch.sweep("encode", "meshes") == 0 and mine.exists() and folder.is_dir()
    code = ("from opaline import scratch; import os\n"
            "fd, path = scratch.owned_file('encode', '.mp4'); os._exit(0)")
    subprocess.run([sys.executable, "-c", code], check=True, env=loopback_env())
    (dead,) = [p for p in tmp_path.glob("opaline-encode-*") if p != mine]
    assert scratch.sweep("encode") == 1 and not dead.exists()  # its lock died with it
    young = tmp_path / f"opaline-encode-{os.getpid()}-x.mp4"  # not locked yet: spared
    young.touch()
    assert scratch.sweep("encode") == 0 and young.exists()
    old = time.time() - 2 * scratch.YOUNG_S
    os.utime(young, (old, old))
    assert scratch.sweep("encode") == 1 and not young.exists()
    scratch.release(fd, mine)
    scratch.release(lock, folder)
    assert list(tmp_path.iterdir()) == []
