"""A hard ceiling on the memory a mesh parse may take: RLIMIT_AS, lowered for the parse.

The checks in ``meshlimits`` refuse what a file declares past the limits before
trimesh builds anything; this is the backstop for what they do not foresee (a
parser's own blow-up on a file that looks small). For the span of one parse the
process's address space may grow by ``headroom`` bytes at most; past that an
allocation fails with MemoryError, which the loader answers as a refused file
(422), and the limit is put back as it was. Only render workers set a headroom
(``limit_parse_memory``, from ``workers.child``): a library user's own process,
with threads of its own, is left alone. Linux only (``/proc/self/statm``);
elsewhere nothing is limited.
"""

from __future__ import annotations

import resource
from collections.abc import Iterator
from contextlib import contextmanager

# A binary STL at the largest upload (64 MiB, 1.3M triangles) grows a worker's address
# space by ~870 MB while trimesh reads it; a 2M-triangle GLB by ~400 MB, PLY ~520 MB.
PARSE_HEADROOM_BYTES = 1 << 30

_headroom: int | None = None


def limit_parse_memory(headroom: int | None = PARSE_HEADROOM_BYTES) -> None:
    """Parses in this process may grow its address space by ``headroom`` (None: unlimited)."""
    global _headroom
    _headroom = headroom


def parse_headroom() -> int | None:
    return _headroom


def address_space_bytes() -> int | None:
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * resource.getpagesize()
    except (OSError, ValueError, IndexError):
        return None


@contextmanager
def parse_ceiling() -> Iterator[None]:
    """Within: the address space may grow by the headroom, no more (MemoryError past it)."""
    now = address_space_bytes()
    if _headroom is None or now is None:
        yield
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    ceiling = now + _headroom
    if hard != resource.RLIM_INFINITY:
        ceiling = min(ceiling, hard)
    if soft != resource.RLIM_INFINITY and soft <= ceiling:
        yield  # already held lower than this
        return
    resource.setrlimit(resource.RLIMIT_AS, (ceiling, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
