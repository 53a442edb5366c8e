"""The image cache: byte-bounded LRU, keys, ETags and If-None-Match matching."""

from __future__ import annotations

import threading

from opaline.model.params import Material
from opaline.server.cache import ImageCache, etag, matches, mdf_key


def test_get_returns_what_was_put():
    """A stored image comes back byte for byte; an unknown key gives None."""
    cache = ImageCache(100)
    cache.put("a", b"12345")
    assert cache.get("a") == b"12345"
    assert cache.get("b") is None


def test_evicts_least_recently_used_to_stay_within_budget():
    """Over the byte budget, the least recently used images go first."""
    cache = ImageCache(10)
    cache.put("a", b"aaaa")
    cache.put("b", b"bbbb")
    cache.get("a")  # now b is the least recently used
    cache.put("c", b"cccc")
    assert cache.get("b") is None
    assert cache.get("a") == b"aaaa" and cache.get("c") == b"cccc"
    assert cache.size_bytes == 8 and len(cache) == 2


def test_budget_counts_bytes_not_entries():
    """One large image can push out several small ones."""
    cache = ImageCache(10)
    for key in "abcde":
        cache.put(key, b"xx")
    cache.put("big", b"y" * 9)
    assert len(cache) == 1 and cache.get("big") is not None
    assert cache.size_bytes == 9


def test_image_larger_than_budget_is_not_kept():
    """An image over the whole budget is not stored and evicts nothing."""
    cache = ImageCache(10)
    cache.put("a", b"aaaa")
    cache.put("huge", b"z" * 11)
    assert cache.get("huge") is None
    assert cache.get("a") == b"aaaa"


def test_zero_budget_keeps_nothing():
    """A budget of 0 turns the cache off."""
    cache = ImageCache(0)
    cache.put("a", b"a")
    assert cache.get("a") is None and cache.size_bytes == 0


def test_replacing_a_key_recounts_its_bytes():
    """Putting the same key again replaces its bytes in the count."""
    cache = ImageCache(100)
    cache.put("a", b"x" * 30)
    cache.put("a", b"x" * 10)
    assert cache.size_bytes == 10 and len(cache) == 1


def test_concurrent_puts_keep_the_count_exact():
    """Puts from several threads leave the byte count equal to the stored images' sizes."""
    cache = ImageCache(5_000)

    def fill(prefix: str) -> None:
        for i in range(500):
            cache.put(f"{prefix}{i}", b"x" * (1 + i % 7))
            cache.get(f"{prefix}{i // 2}")

    threads = [threading.Thread(target=fill, args=(p,)) for p in "abcd"]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    stored = sum(len(data) for data in cache._items.values())
    assert cache.size_bytes == stored <= 5_000


def test_etag_is_strong_and_quoted():
    """The ETag is a quoted opaque tag with no weak prefix."""
    tag = etag(b"abc123")
    assert tag.startswith('"') and tag.endswith('"') and not tag.startswith("W/")


def test_etag_is_the_bytes_not_who_drew_them():
    """Equal bytes get equal tags, whichever replica made them; one byte more, another tag."""
    assert etag(b"\x89PNG image") == etag(b"\x89PNG image")
    assert etag(b"\x89PNG image") != etag(b"\x89PNG image!")


def test_cache_keeps_tags_after_the_image_leaves():
    """A GET can be answered 304 for an image evicted (or never kept: cache size 0)."""
    cache = ImageCache(0)
    cache.put("k", b"bytes")
    assert cache.get("k") is None and cache.tag("k") == etag(b"bytes")
    assert cache.tag("other") is None


def test_if_none_match_matching():
    """If-None-Match matches its exact tag, a weak form of it, a list holding it, and '*'."""
    tag = etag(b"k")
    assert matches(tag, tag)
    assert matches(f"W/{tag}", tag)
    assert matches(f'"other", {tag}', tag)
    assert matches("*", tag)
    assert not matches('"other"', tag)
    assert not matches(None, tag)
    assert not matches("", tag)


def test_mdf_key_changes_with_every_input():
    """The MDF plot key differs when the material, size, format or wavelengths differ."""
    base = mdf_key(Material(), 64, "png", 0)
    assert base == mdf_key(Material(), 64, "png", 0)
    others = {
        mdf_key(Material(mu_f=3.0), 64, "png", 0),
        mdf_key(Material(), 128, "png", 0),
        mdf_key(Material(), 64, "npy", 0),
        mdf_key(Material(), 64, "png", 16),
    }
    assert base not in others and len(others) == 4
