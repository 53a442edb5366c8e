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


class StoreFull(PublicError):
    """Every record kept is a running job's: a new one would evict one (429)."""

    status, reason, retry_later = 429, "busy", True


def running(record: Record) -> bool:
    """A running job's record: never evicted to make room (its job would stop)."""
    return record.value.get("state") == "running"


class LocalState:
    """This process's memory: bounded by count (``KEPT``), lifetime and, for the bytes,
    ``bytes_budget`` (the newest value kept even alone over it); lost at exit."""

    shared = False

    def __init__(self, budget: int, bytes_budget: int | None = None) -> None:
        self.budget = budget
        self.bytes_budget = budget if bytes_budget is None else bytes_budget
        self._bytes: OrderedDict[str, tuple[bytes, float]] = OrderedDict()
        self._records: OrderedDict[str, tuple[Record, float]] = OrderedDict()
        self._total = 0  # bytes of the values in _bytes

    @staticmethod
    def _live(found: tuple[V, float] | None) -> V | None:
        return None if found is None or found[1] < time.monotonic() else found[0]

    def put(self, key: str, data: bytes, ttl_s: float | None = None) -> None:
        self.delete(key)
        self._bytes[key] = (data, time.monotonic() + (ttl_s or float("inf")))
        self._total += len(data)
        while len(self._bytes) > 1 and (len(self._bytes) > KEPT
                                        or self._total > self.bytes_budget):
            self._total -= len(self._bytes.popitem(last=False)[1][0])

    def get(self, key: str) -> bytes | None:
        return self._live(self._bytes.get(key))

    def touch(self, key: str) -> bool:
        return self.get(key) is not None

    def delete(self, key: str) -> None:
        found = self._bytes.pop(key, None)
        if found is not None:
            self._total -= len(found[0])

    def record(self, key: str) -> Record | None:
        return self._live(self._records.get(key))

    def put_record(self, key: str, value: dict[str, Any], expect: int,
                   ttl_s: float) -> int | None:
        found = self.record(key)
        if (found.version if found else 0) != expect:
            return None
        if key not in self._records and len(self._records) >= KEPT:
            self._forget_one()
        self._records[key] = (Record(expect + 1, value), time.monotonic() + ttl_s)
        self._records.move_to_end(key)
        return expect + 1

    def _forget_one(self) -> None:
        """Make room for a record: the oldest expired or finished one goes; a running
        one never (its job would stop itself), so with only those kept: StoreFull."""
        now = time.monotonic()
        for key, (record, until) in self._records.items():
            if until < now or not running(record):
                del self._records[key]
                return
        raise StoreFull(f"{len(self._records)} turntables are running, the most this "
                        "service keeps: retry when one has finished")
