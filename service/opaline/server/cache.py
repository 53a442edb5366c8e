"""The image cache: encoded images in memory, least recently used first out.

Keys are ``Job.cache_key(preset.scene_key())`` for renders and ``mdf_key``
for MDF plots; both already hash the shader sources and the version, so a
key names one image for good. The budget counts the images' bytes; an image
larger than the whole budget is not kept. Thread-safe: render workers store
into it while the event loop reads from it.
"""

from __future__ import annotations

import hashlib
import threading

from opaline.lru import BudgetLRU
from opaline.model.params import Material
from opaline.model.request import content_key


class ImageCache:
    """An LRU mapping of key → encoded image bytes, bounded by their total size."""

    def __init__(self, budget_bytes: int) -> None:
        self.budget = budget_bytes
        self._items: BudgetLRU[str, bytes] = BudgetLRU(max_items=1 << 30, max_bytes=budget_bytes)
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._items)

    @property
    def size_bytes(self) -> int:
        return self._items.size_bytes

    @property
    def evictions(self) -> int:
        return self._items.evictions

    def get(self, key: str) -> bytes | None:
        with self._lock:
            return self._items.get(key)

    def put(self, key: str, data: bytes) -> None:
        with self._lock:
            self._items.put(key, data, len(data))


def mdf_key(material: Material, size: int, fmt: str, wavelengths: int) -> str:
    """Cache key of an MDF plot, hashed like ``Job.cache_key``."""
    return content_key({"mdf_plot": material.model_dump(mode="json"), "size": size,
                        "format": fmt, "wavelengths": wavelengths})


def etag(key: str, renderer: str = "") -> str:
    """A strong ETag for the image under ``key`` as drawn by ``renderer``.

    The same request gives the same bytes on the same GL implementation
    (docs/design.md §9), not across implementations, so the renderer's identity is
    part of the tag: replicas on different hardware do not share validators.
    """
    if not renderer:
        return f'"{key}"'
    digest = hashlib.sha256(f"{key}\0{renderer}".encode()).hexdigest()[:32]
    return f'"{digest}"'


def matches(if_none_match: str | None, tag: str) -> bool:
    """Whether an ``If-None-Match`` header matches ``tag`` (weak comparison, RFC 9110 §13.1.2)."""
    if not if_none_match:
        return False
    if if_none_match.strip() == "*":
        return True
    candidates = (part.strip().removeprefix("W/") for part in if_none_match.split(","))
    return tag.removeprefix("W/") in candidates
