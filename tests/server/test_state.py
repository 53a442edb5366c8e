"""The state store of OPALINE_STATE_URL against a real redis-server (tests/redis_helpers.py):
bytes with lifetimes or under the budget (LRU), compare-and-set records, meshes shared by
two replicas' mesh stores, and a store that is down answering 503 quickly, then recovering.
The GL-free half; the HTTP half is in test_state_http.py and test_deploy_nginx.py."""

from __future__ import annotations

import time

import pytest

from opaline.server.api import open_state
from opaline.server.meshstore import MeshStore, UnknownMesh
from opaline.server.redisstate import RedisState, public_address
from opaline.server.statestore import LocalState, StoreUnavailable
from opaline.server.turntable_jobs import StoredFailure, failure_of
from opaline.settings import Settings
from opaline.workers.errors import DeadlineExceeded
from redis_helpers import LocalRedis


@pytest.fixture(scope="module")
def server():
    with LocalRedis() as redis:
        yield redis


@pytest.fixture
def store(server):
    state = RedisState(server.url, budget=3000, timeout_s=0.5)
    state.client.flushdb()
    return state


def test_bytes_without_a_lifetime_stay_under_the_budget_least_recently_used_first(store):
    for name in "abc":
        store.put(name, name.encode() * 1000)
    assert store.get("a") == b"a" * 1000  # a is now the most recent: b goes first
    store.put("d", b"d" * 1000)
    assert store.get("b") is None and store.evictions == 1
    assert [store.get(n) is not None for n in "acd"] == [True, True, True]
    store.put("e", b"e" * 5000)  # alone over the budget: kept (the newest), all else goes
    assert store.get("e") is not None and all(store.get(n) is None for n in "acd")
    store.delete("e")
    assert store.get("e") is None and int(store.client.get("opaline:lru-bytes")) == 0


def test_bytes_with_a_lifetime_expire_and_do_not_count_against_the_budget(store):
    store.put("result", b"x" * 10_000, ttl_s=0.2)
    store.put("mesh", b"m" * 2000)
    assert store.get("result") == b"x" * 10_000 and store.get("mesh") is not None
    time.sleep(0.3)
    assert store.get("result") is None and store.get("mesh") is not None


@pytest.mark.parametrize("kind", ["redis", "local"])
def test_records_are_compared_and_set(kind, server):
    one = RedisState(server.url, 1000) if kind == "redis" else LocalState(1000)
    two = RedisState(server.url, 1000) if kind == "redis" else one  # another replica
    if kind == "redis":
        one.client.flushdb()
    assert one.record("job") is None and one.put_record("job", {"n": 1}, 1, 60) is None
    assert one.put_record("job", {"n": 1}, 0, 60) == 1
    assert two.put_record("job", {"n": 2}, 0, 60) is None  # the loser of a race to create
    assert two.put_record("job", {"n": 2}, 1, 60) == 2
    assert one.put_record("job", {"n": 3}, 1, 60) is None  # a stale writer
    assert one.record("job").value == {"n": 2} and one.record("job").version == 2


def test_a_mesh_uploaded_through_one_replica_resolves_on_another(store, tmp_path):
    settings = Settings(mesh_store_bytes=3000, mesh_max_bytes=2000)
    a = MeshStore(settings.model_copy(update={"mesh_store_dir": tmp_path / "a"}), store)
    b = MeshStore(settings.model_copy(update={"mesh_store_dir": tmp_path / "b"}), store)
    mesh_id = a.put(b"solid x\n" * 100)
    path, digest = b.resolve(mesh_id)
    assert digest == mesh_id and path.parent == tmp_path / "b"
    assert path.read_bytes() == b"solid x\n" * 100
    with pytest.raises(UnknownMesh):
        b.resolve("0" * 32)


def test_a_store_that_is_down_answers_503_quickly_and_recovers(server, tmp_path):
    store = RedisState(server.url, 3000, timeout_s=0.5)
    settings = Settings(mesh_store_dir=tmp_path, mesh_max_bytes=2000)
    meshes = MeshStore(settings, store)
    kept = meshes.put(b"ply kept" * 10)
    server.stop()
    try:
        started = time.monotonic()
        with pytest.raises(StoreUnavailable) as caught:
            meshes.put(b"ply new" * 10)
        assert time.monotonic() - started < 2.0
        assert caught.value.status == 503 and caught.value.retry_later
        assert str(caught.value).startswith(f"the state store {server.url} did not answer (")
        assert meshes.resolve(kept)[1] == kept  # a copy here renders while the store is down
        with pytest.raises(StoreUnavailable):
            store.record("turntable:x")
    finally:
        server.start()
    assert meshes.put(b"ply new" * 10) and store.record("turntable:x") is None


def test_the_store_is_chosen_by_its_url_and_never_shows_a_password(server):
    assert isinstance(open_state(Settings()), LocalState)
    assert isinstance(open_state(Settings(state_url=server.url)), RedisState)
    assert public_address("redis://user:secret@db:6380/2") == "redis://db:6380/2"
    with pytest.raises(ValueError):
        Settings(state_url="http://db:6379")


def test_a_failure_kept_in_a_record_answers_as_it_was_raised():
    stored = StoredFailure(failure_of(DeadlineExceeded("no image in 2 s")))
    original = DeadlineExceeded("no image in 2 s")
    assert (stored.status, stored.reason, stored.lines(), stored.headers(1)) == (
        original.status, original.reason, original.lines(), original.headers(1))
