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

# Validators of images rendered here, kept apart from the images (and longer: ~150 bytes
# each), so a GET with If-None-Match is answered 304 after its image left the cache.
MAX_TAGS = 1 << 16


class ImageCache:
    """An LRU mapping of key → encoded image bytes, bounded by their total size, and of
    key → the image's ETag, bounded by count."""

    def __init__(self, budget_bytes: int) -> None:
        self.budget = budget_bytes
        self._items: BudgetLRU[str, bytes] = BudgetLRU(max_items=1 << 30, max_bytes=budget_bytes)
        self._tags: BudgetLRU[str, str] = BudgetLRU(max_items=MAX_TAGS, max_bytes=1 << 62)
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
        tag = etag(data)
        with self._lock:
            self._items.put(key, data, len(data))
            self._tags.put(key, tag, 1)

    def tag(self, key: str) -> str | None:
        """The ETag of the image last rendered here under ``key``, if still known."""
        with self._lock:
            return self._tags.get(key)


def mdf_key(material: Material, size: int, fmt: str, wavelengths: int) -> str:
    """Cache key of an MDF plot, hashed like ``Job.cache_key``."""
    return content_key({"mdf_plot": material.model_dump(mode="json"), "size": size,
                        "format": fmt, "wavelengths": wavelengths})


def etag(data: bytes) -> str:
    """The strong ETag of an encoded image: a hash of its bytes (docs/design.md, deployment).

    Not of the request: replicas on the same GL implementation draw the same bytes and so
    answer the same tag, whichever of them rendered; a replica on another GPU or driver,
    whose bytes may differ, answers another tag, as a strong validator must.
    """
    return f'"{hashlib.sha256(data).hexdigest()[:32]}"'


def matches(if_none_match: str | None, tag: str) -> bool:
    """Whether an ``If-None-Match`` header matches ``tag`` (weak comparison, RFC 9110 §13.1.2)."""
    if not if_none_match:
        return False
    if if_none_match.strip() == "*":
        return True
    candidates = (part.strip().removeprefix("W/") for part in if_none_match.split(","))
    return tag.removeprefix("W/") in candidates
