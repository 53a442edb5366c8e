"""A least-recently-used map bounded by item count and by bytes.

Everything a long-lived process keeps for reuse (compiled programs, uploaded
scenes, framebuffers, encoded images) goes through one of these, so that no
sequence of requests can make it grow past its budget. ``release`` is called
on each value that leaves, so GL objects are freed by the thread that owns the
context (the one calling ``put``), never by Python's collector.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class BudgetLRU(Generic[K, V]):
    """At most ``max_items`` values and ``max_bytes`` bytes; the oldest leave first."""

    def __init__(self, max_items: int, max_bytes: int,
                 release: Callable[[V], None] | None = None) -> None:
        if max_items < 1 or max_bytes < 0:
            raise ValueError(f"budget must be ≥ 1 item and ≥ 0 bytes, got {max_items}, {max_bytes}")
        self.max_items = max_items
        self.max_bytes = max_bytes
        self.release = release
        self.evictions = 0
        self._items: OrderedDict[K, tuple[V, int]] = OrderedDict()
        self._bytes = 0

    def __len__(self) -> int:
        return len(self._items)

    def __contains__(self, key: object) -> bool:
        return key in self._items

    @property
    def size_bytes(self) -> int:
        return self._bytes

    def get(self, key: K) -> V | None:
        found = self._items.get(key)
        if found is None:
            return None
        self._items.move_to_end(key)
        return found[0]

    def put(self, key: K, value: V, nbytes: int) -> bool:
        """Keep ``value``; older values leave until both budgets hold. A value larger than
        the whole byte budget is not kept (``False``): the caller must release it itself."""
        self.discard(key)
        if nbytes > self.max_bytes:
            return False
        self._items[key] = (value, nbytes)
        self._bytes += nbytes
        while len(self._items) > self.max_items or self._bytes > self.max_bytes:
            old_key = next(iter(self._items))
            self._evict(old_key)
            self.evictions += 1
        return True

    def discard(self, key: K) -> None:
        if key in self._items:
            self._evict(key)

    def values(self) -> list[V]:
        return [value for value, _ in self._items.values()]

    def clear(self) -> None:
        while self._items:
            self._evict(next(iter(self._items)))

    def _evict(self, key: K) -> None:
        value, nbytes = self._items.pop(key)
        self._bytes -= nbytes
        if self.release is not None:
            self.release(value)
