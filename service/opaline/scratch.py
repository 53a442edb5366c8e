"""Temporary files and folders that no way of dying leaves behind for good.

Each is named ``opaline-<kind>-<pid>-<random>`` and holds an exclusive ``flock``
while its owner lives: a file on itself, a folder on its ``.owner`` file. The
kernel drops the lock however the owner ends (SIGKILL and the OOM killer
included), so ``sweep`` can tell what a dead process left from what a live one
is writing, even where pids are reused (a container's service is often pid 1 on
every start). Owners remove their own on every orderly exit; ``sweep`` at the
next start-up (and before each new one of its kind) removes the rest.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import tempfile
import time
from pathlib import Path

OWNER = ".owner"
WORKER_KINDS = ("encode", "decode")  # what render workers make: MP4s passed to ffmpeg
# Between creating a name and locking it there are microseconds; a name this young is
# never taken for a dead one's, even unlocked.
YOUNG_S = 10.0


def _prefix(kind: str) -> str:
    return f"opaline-{kind}-{os.getpid()}-"


def _lock(fd: int) -> None:
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


def owned_file(kind: str, suffix: str = "", folder: Path | None = None) -> tuple[int, Path]:
    """A new file, locked by the returned descriptor until it is closed."""
    fd, path = tempfile.mkstemp(prefix=_prefix(kind), suffix=suffix, dir=folder)
    _lock(fd)
    return fd, Path(path)


def owned_dir(kind: str) -> tuple[int, Path]:
    """A new folder under the temporary directory, locked by the returned descriptor."""
    path = Path(tempfile.mkdtemp(prefix=_prefix(kind)))
    fd = os.open(path / OWNER, os.O_CREAT | os.O_RDWR | os.O_CLOEXEC, 0o600)
    _lock(fd)
    return fd, path


def _pid(name: str, kind: str) -> int | None:
    digits = name[len(f"opaline-{kind}-"):].partition("-")[0]
    return int(digits) if digits.isdigit() else None


def _alive(pid: int | None) -> bool:
    if pid is None:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        pass
    return True


def _unlocked(path: Path) -> bool:
    """Whether no process holds the lock of ``path`` (a file or a folder's owner file)."""
    target = path / OWNER if path.is_dir() else path
    try:
        fd = os.open(target, os.O_RDONLY | os.O_CLOEXEC)
    except FileNotFoundError:
        return True
    try:
        _lock(fd)
    except BlockingIOError:
        return False
    finally:
        os.close(fd)  # also drops the lock this may have taken
    return True


def sweep(*kinds: str, folder: Path | None = None) -> int:
    """Remove what dead owners left of ``kinds`` in ``folder`` (the temporary directory by
    default); the number removed."""
    root = Path(folder if folder is not None else tempfile.gettempdir())
    removed = 0
    found = [(kind, path) for kind in kinds for path in root.glob(f"opaline-{kind}-*")]
    for kind, path in found:
        try:
            young = time.time() - path.lstat().st_mtime < YOUNG_S
            if not _unlocked(path) or (young and _alive(_pid(path.name, kind))):
                continue
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)
            removed += 1
        except OSError:  # gone meanwhile, or not ours to remove
            continue
    return removed


def release(fd: int, path: Path) -> None:
    """Remove an owned file or folder and drop its lock."""
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)
    try:
        os.close(fd)
    except OSError:
        pass
