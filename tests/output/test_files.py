"""write_atomic: whole files, and never a device, a pipe or a link replaced by one."""

from __future__ import annotations

import os
import stat
import threading

import pytest

from opaline.output.files import write_atomic


def test_a_symlink_is_followed_and_kept(tmp_path):
    target = tmp_path / "real" / "image.png"
    target.parent.mkdir()
    target.write_bytes(b"old")
    link = tmp_path / "link.png"
    link.symlink_to(target)
    write_atomic(link, b"new")
    assert link.is_symlink()
    assert target.read_bytes() == b"new"


def test_a_fifo_is_written_into_not_replaced(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)  # left waiting if the pipe was replaced
    reader.start()
    write_atomic(fifo, b"image bytes")
    reader.join(timeout=10)
    assert got == [b"image bytes"]
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.png"]


def test_a_character_device_is_written_into_not_replaced():
    write_atomic(os.devnull, b"discarded")
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)


def test_a_directory_is_refused(tmp_path):
    with pytest.raises(IsADirectoryError):
        write_atomic(tmp_path, b"data")
    assert list(tmp_path.iterdir()) == []
