"""``OPALINE_STATE_URL=redis://host:port/db``: the state every replica shares, in Redis.

Each step that must not be split (store and evict, compare and set) is one Lua
script, which Redis runs alone. Bytes without a lifetime are kept under the
budget by an LRU of this module's own (a sorted set by last use, a total), not
by Redis's ``maxmemory`` policy: that would evict turntable records too. Every
call has socket timeouts and one retry on a dropped connection (a Redis that
restarted), so a store that is down answers ``StoreUnavailable`` within about a
second and never hangs a request.
"""

from __future__ import annotations

import json
from typing import Any
from urllib.parse import urlsplit

import redis
from redis.backoff import NoBackoff
from redis.retry import Retry

from opaline.server.statestore import Record, StoreUnavailable

PREFIX = "opaline:"
LRU, TOTAL, CLOCK = PREFIX + "lru", PREFIX + "lru-bytes", PREFIX + "lru-clock"

# KEYS: value, lru, total, clock; ARGV: data, budget. Answers how many were evicted.
PUT_KEPT = """
local old = redis.call('STRLEN', KEYS[1])
redis.call('SET', KEYS[1], ARGV[1])
redis.call('ZADD', KEYS[2], redis.call('INCR', KEYS[4]), KEYS[1])
local total = redis.call('INCRBY', KEYS[3], string.len(ARGV[1]) - old)
local evicted = 0
while total > tonumber(ARGV[2]) do
  local oldest = redis.call('ZRANGE', KEYS[2], 0, 0)[1]
  if not oldest or oldest == KEYS[1] then break end
  total = redis.call('INCRBY', KEYS[3], -redis.call('STRLEN', oldest))
  redis.call('DEL', oldest)
  redis.call('ZREM', KEYS[2], oldest)
  evicted = evicted + 1
end
return evicted
"""
# KEYS: value, lru, clock. Answers 1 if the value exists (and is now the most recent).
TOUCH = """
if redis.call('EXISTS', KEYS[1]) == 0 then return 0 end
if redis.call('ZSCORE', KEYS[2], KEYS[1]) then
  redis.call('ZADD', KEYS[2], redis.call('INCR', KEYS[3]), KEYS[1])
end
return 1
"""
# KEYS: value, lru, total.
DELETE = """
if redis.call('ZREM', KEYS[2], KEYS[1]) == 1 then
  redis.call('INCRBY', KEYS[3], -redis.call('STRLEN', KEYS[1]))
end
return redis.call('DEL', KEYS[1])
"""
# KEYS: record; ARGV: expected version, JSON, lifetime in ms. Answers the new version or 0.
PUT_RECORD = """
local version = tonumber(redis.call('HGET', KEYS[1], 'v') or '0')
if version ~= tonumber(ARGV[1]) then return 0 end
redis.call('HSET', KEYS[1], 'v', version + 1, 'data', ARGV[2])
redis.call('PEXPIRE', KEYS[1], ARGV[3])
return version + 1
"""


def public_address(url: str) -> str:
    """The URL without its password, as messages show it."""
    parts = urlsplit(url)
    return f"{parts.scheme}://{parts.hostname}:{parts.port or 6379}{parts.path}"


class RedisState:
    shared = True

    def __init__(self, url: str, budget: int, timeout_s: float = 1.0) -> None:
        self.budget = budget
        self.address = public_address(url)
        self.client = redis.Redis.from_url(
            url, socket_timeout=timeout_s, socket_connect_timeout=timeout_s,
            retry=Retry(NoBackoff(), 1), health_check_interval=30)
        self._put_kept = self.client.register_script(PUT_KEPT)
        self._touch = self.client.register_script(TOUCH)
        self._delete = self.client.register_script(DELETE)
        self._put_record = self.client.register_script(PUT_RECORD)
        self.evictions = 0

    def _call(self, step: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return step(*args, **kwargs)
        except redis.RedisError as exc:  # down, timed out, out of memory, read-only ...
            raise StoreUnavailable(
                f"the state store {self.address} did not answer "
                f"({type(exc).__name__}: {exc})") from None

    def put(self, key: str, data: bytes, ttl_s: float | None = None) -> None:
        if ttl_s is None:
            self.evictions += self._call(self._put_kept, [PREFIX + key, LRU, TOTAL, CLOCK],
                                         [data, self.budget])
        else:
            self._call(self.client.set, PREFIX + key, data, px=max(1, int(ttl_s * 1000)))

    def get(self, key: str) -> bytes | None:
        data: bytes | None = self._call(self.client.get, PREFIX + key)
        if data is not None:
            self.touch(key)
        return data

    def touch(self, key: str) -> bool:
        return bool(self._call(self._touch, [PREFIX + key, LRU, CLOCK]))

    def delete(self, key: str) -> None:
        self._call(self._delete, [PREFIX + key, LRU, TOTAL])

    def record(self, key: str) -> Record | None:
        found = self._call(self.client.hmget, PREFIX + key, ["v", "data"])
        if found[0] is None:
            return None
        return Record(int(found[0]), json.loads(found[1]))

    def put_record(self, key: str, value: dict[str, Any], expect: int,
                   ttl_s: float) -> int | None:
        version = self._call(self._put_record, [PREFIX + key],
                             [expect, json.dumps(value), max(1, int(ttl_s * 1000))])
        return int(version) or None
