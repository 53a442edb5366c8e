"""Where the state that must outlive one request lives: ``OPALINE_STATE_URL``.

Two kinds of thing, behind one small interface that the mesh store and the
turntables sit on:

- bytes under a key (``put``/``get``/``touch``/``delete``): with a lifetime, they expire
  (turntable results); without one, they are kept under the store's byte budget,
  the least recently used evicted first (uploaded meshes);
- records (``record``/``put_record``): a small JSON object with a version, written
  only if the version is still the one read (compare and set), so two replicas
  never both take the same turntable.

``LocalState`` (no URL: this process, in memory) is what one machine had before;
``redisstate.RedisState`` (``redis://host:port/db``) is shared by every replica.
A store that does not answer raises ``StoreUnavailable``: 503 with Retry-After.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar

from opaline.errors import PublicError

V = TypeVar("V")
KEPT = 64  # records (and byte values) LocalState keeps, the oldest forgotten first


class StoreUnavailable(PublicError):
    """The shared state store did not answer (503 with Retry-After)."""

    status, reason, retry_later = 503, "store_unavailable", True


@dataclass(frozen=True)
class Record:
    version: int  # 0: absent
    value: dict[str, Any]


class StateStore(Protocol):
    shared: bool  # whether other replicas see what this one writes
    budget: int  # bytes kept without a lifetime

    def put(self, key: str, data: bytes, ttl_s: float | None = None) -> None: ...

    def get(self, key: str) -> bytes | None: ...

    def touch(self, key: str) -> bool: ...

    def delete(self, key: str) -> None: ...

    def record(self, key: str) -> Record | None: ...

    def put_record(self, key: str, value: dict[str, Any], expect: int,
                   ttl_s: float) -> int | None: ...


class LocalState:
    """This process's memory: bounded by count (``KEPT``) and lifetime, lost at exit."""

    shared = False

    def __init__(self, budget: int) -> None:
        self.budget = budget
        self._bytes: OrderedDict[str, tuple[bytes, float]] = OrderedDict()
        self._records: OrderedDict[str, tuple[Record, float]] = OrderedDict()

    @staticmethod
    def _live(found: tuple[V, float] | None) -> V | None:
        return None if found is None or found[1] < time.monotonic() else found[0]

    def put(self, key: str, data: bytes, ttl_s: float | None = None) -> None:
        self._bytes[key] = (data, time.monotonic() + (ttl_s or float("inf")))
        self._bytes.move_to_end(key)
        while len(self._bytes) > KEPT:
            self._bytes.popitem(last=False)

    def get(self, key: str) -> bytes | None:
        return self._live(self._bytes.get(key))

    def touch(self, key: str) -> bool:
        return self.get(key) is not None

    def delete(self, key: str) -> None:
        self._bytes.pop(key, None)

    def record(self, key: str) -> Record | None:
        return self._live(self._records.get(key))

    def put_record(self, key: str, value: dict[str, Any], expect: int,
                   ttl_s: float) -> int | None:
        found = self.record(key)
        if (found.version if found else 0) != expect:
            return None
        self._records[key] = (Record(expect + 1, value), time.monotonic() + ttl_s)
        self._records.move_to_end(key)
        while len(self._records) > KEPT:  # a running turntable forgotten here stops itself
            self._records.popitem(last=False)
        return expect + 1
