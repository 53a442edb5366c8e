"""Debian's nginx in front of two replicas, all on loopback: the deployment of deploy/nginx.

Shows, with the figures printed (pytest -s): a miss on one replica is a hit for
requests that the balancer routes to the other; 50 concurrent equal requests
render once across both replicas; killing a replica mid-run loses no request
the other can serve. The replicas share a real Redis (OPALINE_STATE_URL): a mesh
uploaded through the proxy renders on both, a turntable answers from either, one
whose replica is killed mid-run is finished by the other, and with the store stopped
only the state routes answer 503 (plain renders go on; nginx rests no replica). The mesh and turntable tests
run again on one replica with the default embedded state (no OPALINE_STATE_URL, no
Redis). Bounded: small images, about 45 s in all on 2 cores.
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import httpx
import pytest

from mesh_helpers import mesh_bytes
from opaline.batch.run import Options, run_batch
from opaline.model.params import RenderRequest
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, prepare
from opaline.server.localproxy import LocalProxy, nginx_binary
from opaline.server.localserver import LocalServer
from redis_helpers import LocalRedis, need_redis

pytestmark = pytest.mark.gl
REPLICA_ENV = {"OPALINE_CALIBRATE": "0", "OPALINE_QUEUE_SIZE": "64", "OPALINE_DEADLINE_S": "30",
               "OPALINE_STATE_LEASE_S": "2"}
PRESET = "cd-rom"  # the warm-up renders "sphere": counting cd-rom renders counts ours only


def url(**fields) -> str:
    """The canonical URL, as a client learns it from Content-Location."""
    request = RenderRequest(**{"preset": PRESET, "quality": "draft", **fields})
    return prepare(request, Context(Limits(cost_budget=None), lambda r, p: p)).url()


def renders(replica: LocalServer) -> float:
    """Renders of PRESET this replica has made (its /metrics)."""
    text = httpx.get(replica.base + "/metrics", trust_env=False).text
    found = re.search(rf'^opaline_render_seconds_count\{{preset="{PRESET}"\}} (\S+)$', text, re.M)
    return float(found.group(1)) if found else 0.0


def log_lines(proxy: LocalProxy, path: str, count: int = 1) -> list[str]:
    """nginx's log lines for ``path``; it writes one just after answering, so wait for
    ``count`` of them (a second at most)."""
    deadline = time.monotonic() + 1.0
    while True:
        lines = [line for line in proxy.log().splitlines() if f'"GET {path} ' in line]
        if len(lines) >= count or time.monotonic() > deadline:
            return lines
        time.sleep(0.01)


def upstream(line: str) -> str:
    """Which replica answered: '-' for the cache, 'A, B' when A failed and B answered."""
    return re.search(r" up=(.*?) cache=", line).group(1)


def need_nginx() -> None:
    if nginx_binary() is None:
        if os.environ.get("CI"):
            pytest.fail("nginx is missing: scripts/test installs it (OPALINE_EXTRA_DEBS)")
        pytest.skip("nginx is not installed (apt-get install nginx-light)")


@pytest.fixture(scope="module")
def store():
    need_redis()
    with LocalRedis() as redis:
        yield redis


@pytest.fixture(scope="module")
def deployment(store):
    need_nginx()
    env = {**REPLICA_ENV, "OPALINE_STATE_URL": store.url}
    with (LocalServer(env=env) as a, LocalServer(env=env) as b,
          LocalProxy([a.base, b.base]) as proxy,
          httpx.Client(base_url=proxy.base, trust_env=False, timeout=60,
                       limits=httpx.Limits(max_connections=64)) as client):
        yield [a, b], proxy, client


@pytest.fixture(scope="module")
def embedded():
    """One replica keeping its state itself (the default: nothing to install) behind nginx."""
    need_nginx()
    assert "OPALINE_STATE_URL" not in os.environ, "the replica would inherit a shared store"
    with (LocalServer(env=REPLICA_ENV) as a, LocalProxy([a.base]) as proxy,
          httpx.Client(base_url=proxy.base, trust_env=False, timeout=60) as client):
        yield [a], proxy, client


@pytest.fixture(params=["redis", "embedded"])
def stateful(request):
    """The tests of state run on both: two replicas sharing Redis, one with embedded state."""
    return request.getfixturevalue("deployment" if request.param == "redis" else "embedded")


def where(replicas: list[LocalServer]) -> str:
    return "two replicas and Redis" if len(replicas) > 1 else "one replica, embedded state"


def test_a_miss_on_one_replica_is_a_hit_routed_to_the_other(deployment):
    replicas, proxy, client = deployment
    before = [renders(r) for r in replicas]
    first = client.get(url(mu_f=4.25, width=64, height=64))
    assert first.status_code == 200 and first.headers["x-cache-status"] == "MISS"
    routed = set()
    for i in range(6):  # other images between the repeats: round robin visits both replicas
        other = client.get(url(mu_f=1 + i / 8, width=64, height=64))
        assert other.status_code == 200
        routed.add(upstream(log_lines(proxy, url(mu_f=1 + i / 8, width=64, height=64))[0]))
        again = client.get(url(mu_f=4.25, width=64, height=64))
        assert again.headers["x-cache-status"] == "HIT" and again.content == first.content
        assert again.headers["etag"] == first.headers["etag"]
    lines = log_lines(proxy, url(mu_f=4.25, width=64, height=64), 7)
    assert [upstream(line) for line in lines[1:]] == ["-"] * 6  # no replica saw a repeat
    assert routed == {r.base.removeprefix("http://") for r in replicas}
    made = [renders(r) - b for r, b in zip(replicas, before, strict=True)]
    assert sum(made) == 7  # the first image once, six others once each
    print(f"\nshared cache: 1 miss via {upstream(lines[0])}, 6 repeats answered by nginx "
          f"(HIT) while other images went to {sorted(routed)}; renders per replica {made}")


def test_a_burst_of_equal_requests_renders_once(deployment):
    replicas, proxy, client = deployment
    target = url(mu_f=6.5, width=192, height=192, quality="standard")
    before = [renders(r) for r in replicas]
    started = time.monotonic()
    with ThreadPoolExecutor(50) as pool:
        answers = list(pool.map(lambda _: client.get(target), range(50), timeout=60))
    wall = time.monotonic() - started
    assert [a.status_code for a in answers] == [200] * 50
    assert len({a.content for a in answers}) == 1
    made = [renders(r) - b for r, b in zip(replicas, before, strict=True)]
    upstreams = [upstream(line) for line in log_lines(proxy, target, 50)]
    assert sum(made) == 1 and sum(u != "-" for u in upstreams) == 1, (made, upstreams)
    statuses = sorted({a.headers["x-cache-status"] for a in answers})
    print(f"\nburst: 50 equal requests in {wall:.2f} s, renders per replica {made}, "
          f"cache statuses {statuses}")


def test_a_batch_fans_out_over_the_replicas(deployment, tmp_path):
    """`opaline batch --server` with the proxy's URL: the renders spread over both replicas."""
    replicas, proxy, _ = deployment
    folder = tmp_path / "materials"
    folder.mkdir()
    for i in range(12):
        (folder / f"m{i:02d}.toml").write_text(
            f'preset = "{PRESET}"\nmu_f = {7 + i / 9}\nwidth = 64\nheight = 64\n')
    before = [renders(r) for r in replicas]
    summary = run_batch([folder], Options(out=tmp_path / "out", jobs=4, server=proxy.base,
                                          quiet=True))
    made = [renders(r) - b for r, b in zip(replicas, before, strict=True)]
    assert summary["counts"]["rendered"] == 12 and sum(made) == 12
    assert min(made) >= 3, made  # round robin: neither replica idle
    # Again, into another folder: the client GETs canonical URLs, which nginx keeps.
    hits = proxy.log().count(" cache=HIT ")
    again = run_batch([folder], Options(out=tmp_path / "again", jobs=4, server=proxy.base,
                                        quiet=True))
    remade = [renders(r) - b for r, b in zip(replicas, before, strict=True)]
    assert again["counts"]["rendered"] == 12 and remade == made, remade
    deadline = time.monotonic() + 1.0
    while proxy.log().count(" cache=HIT ") < hits + 12 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert proxy.log().count(" cache=HIT ") == hits + 12
    print(f"\nbatch --server via nginx: 12 materials, renders per replica {made}; "
          "run again: 12 nginx HITs, no render")


def test_a_mesh_uploaded_through_the_proxy_renders_on_every_replica(stateful):
    replicas, proxy, client = stateful
    upload = client.post("/v1/meshes", content=mesh_bytes("stl"))
    assert upload.status_code == 201, upload.text
    paths = [f"/v1/render?preset={PRESET}&mesh={upload.json()['id']}&mu_f={1 + i / 19}"
             "&width=48&height=48&quality=draft" for i in range(20)]
    statuses = [client.get(path).status_code for path in paths]  # each a miss: round robin
    assert statuses == [200] * 20, statuses
    routed = [upstream(log_lines(proxy, path)[0]) for path in paths]
    assert set(routed) == {r.base.removeprefix("http://") for r in replicas}
    print(f"\nmeshes on {where(replicas)}: 20 renders of an uploaded mesh, all 200, "
          f"{[routed.count(u) for u in sorted(set(routed))]} via {sorted(set(routed))}")


def test_an_uploaded_mesh_is_described_by_every_replica(stateful):
    """The 201's Location answers the same summary whichever replica takes the GET (one
    that never saw the upload checks the file it fetches from the store)."""
    replicas, proxy, client = stateful
    upload = client.post("/v1/meshes", content=mesh_bytes("obj"))
    assert upload.status_code == 201, upload.text
    path = upload.headers["location"]
    answers = [client.get(path) for _ in range(4)]  # not cached: round robin
    assert [a.status_code for a in answers] == [200] * 4, [a.text for a in answers]
    assert all(a.json() == upload.json() for a in answers)
    routed = {upstream(line) for line in log_lines(proxy, path, count=4)}
    assert routed == {r.base.removeprefix("http://") for r in replicas}, routed


def poll_until_done(clients: list[httpx.Client], path: str) -> list[dict]:
    """GET ``path`` from each client in turn until the turntable is no longer running."""
    seen: list[dict] = []
    deadline = time.monotonic() + 60
    while not seen or seen[-1]["state"] == "running":
        assert time.monotonic() < deadline, seen[-1:]
        for client in clients:
            answer = client.get(path)
            assert answer.status_code == 200, answer.text  # never 404, whoever answers
            seen.append(answer.json())
        time.sleep(0.05)
    return seen


def test_a_turntable_answers_from_either_replica(stateful):
    replicas, proxy, client = stateful
    body = {"preset": PRESET, "frames": 6, "width": 48, "height": 48, "quality": "draft",
            "mu_f": 9.5}
    started = client.post("/v1/turntables", json=body)
    assert started.status_code == 202, started.text
    path = f"/v1/turntables/{started.json()['id']}"
    direct = [httpx.Client(base_url=r.base, trust_env=False, timeout=30) for r in replicas]
    try:
        seen = poll_until_done([client, *direct], path)
        assert seen[-1]["state"] == "done" and seen[-1]["done"] == 6, seen[-1]
        results = [c.get(path + "/result") for c in (client, *direct)]
    finally:
        for c in direct:
            c.close()
    assert [r.status_code for r in results] == [200] * (1 + len(replicas))
    assert len({r.content for r in results}) == 1
    print(f"\nturntables on {where(replicas)}: {len(seen)} polls via the proxy and each "
          "replica, all 200; the result fetched 200 from each")


def test_killing_a_replica_loses_no_request(deployment):
    """A replica crashes (SIGKILL) mid-run. nginx sends every request that it has not begun
    to answer to the survivor. The one thing no streaming proxy can redo is an answer the
    dead replica had begun to send: its client sees the connection cut and asks again
    (a GET is safe to repeat), so only requests in flight at the kill may need that."""
    replicas, proxy, client = deployment
    targets = [url(mu_f=2 + i / 7, width=64, height=64) for i in range(30)]
    done: list[int] = []
    cut: list[float] = []  # when each request that was cut off had started
    killed = [float("inf")]

    def ask(path: str) -> int:
        started = time.monotonic()
        try:
            status = client.get(path).status_code
        except httpx.TransportError:
            cut.append(started)
            status = client.get(path).status_code
        done.append(status)
        return status

    with ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(ask, t) for t in targets]
        while len(done) < 5:
            time.sleep(0.01)
        killed[0] = time.monotonic()
        replicas[0].proc.send_signal(signal.SIGKILL)  # a crash: no graceful shutdown
        killed_after = len(done)
        statuses = [f.result(timeout=60) for f in futures]
    assert statuses == [200] * len(targets), statuses
    assert len(cut) <= 4 and all(started < killed[0] for started in cut)
    ups = [upstream(log_lines(proxy, t)[0]) for t in targets]
    survivor = replicas[1].base.removeprefix("http://")
    # Requests begun after the kill (the pool's 4 threads were busy with earlier ones):
    assert all(u.split(", ")[-1] == survivor for u in ups[killed_after + 4:])
    retried = sum(", " in u for u in ups)
    print(f"\nfail-over: replica killed after {killed_after} of {len(targets)} answers; "
          f"all {len(targets)} answered 200: {retried} retried on the survivor by nginx, "
          f"{len(cut)} cut off mid-answer and asked again by the client")


def test_a_turntable_outlives_the_replica_running_it(store):
    """A turntable started through the proxy, in front of two fresh replicas sharing the
    store; the replica running it (the one whose frame count grows) is killed mid-run. Once
    its lease runs out, the survivor renders the job again from its request: every poll
    through the proxy answers 200 (never 404), and the result comes."""
    need_nginx()
    env = {**REPLICA_ENV, "OPALINE_STATE_URL": store.url}
    body = {"preset": PRESET, "frames": 24, "width": 96, "height": 96, "mu_f": 3.3}
    with (LocalServer(env=env) as a, LocalServer(env=env) as b,
          LocalProxy([a.base, b.base]) as proxy,
          httpx.Client(base_url=proxy.base, trust_env=False, timeout=30) as client):
        started = client.post("/v1/turntables", json=body)
        assert started.status_code == 202, started.text
        path = f"/v1/turntables/{started.json()['id']}"
        seen = []
        while not seen or seen[-1]["done"] < 2:
            answer = client.get(path)
            assert answer.status_code == 200, answer.text
            seen.append(answer.json())
            time.sleep(0.01)
        owner, survivor = (a, b) if renders(a) > renders(b) else (b, a)
        before, at_kill = renders(survivor), seen[-1]["done"]
        owner.proc.send_signal(signal.SIGKILL)
        owner.proc.wait(10)
        seen += poll_until_done([client], path)
        assert seen[-1]["state"] == "done", seen[-1]
        result = client.get(path + "/result")
        assert result.status_code == 200 and len(result.content) > 0
        again = renders(survivor) - before
        assert again >= 24 - 2  # it rendered the frames again
    print(f"\ntake-over: the replica running a turntable started through the proxy killed "
          f"after {at_kill} of 24 frames; {len(seen)} polls via the proxy all 200, the "
          f"survivor finished it ({again:.0f} frames)")


def test_the_store_down_through_the_proxy_is_503_for_state_only_and_recovers():
    """Redis stopped under two replicas behind nginx: an upload, a turntable start, a poll
    and a result answer 503 store_unavailable with Retry-After, whichever replica nginx
    picks; plain renders keep answering 200; once the store is back (empty: this one
    keeps nothing on disk), an upload renders on both replicas and turntables start."""
    need_nginx()
    with LocalRedis() as redis:
        env = {**REPLICA_ENV, "OPALINE_STATE_URL": redis.url, "OPALINE_STATE_TIMEOUT_S": "0.5"}
        with (LocalServer(env=env) as a, LocalServer(env=env) as b,
              LocalProxy([a.base, b.base]) as proxy,
              httpx.Client(base_url=proxy.base, trust_env=False, timeout=30) as client):
            body = {"preset": PRESET, "frames": 3, "width": 48, "height": 48,
                    "quality": "draft", "mu_f": 4.4}
            started = client.post("/v1/turntables", json=body)
            assert started.status_code == 202, started.text
            path = f"/v1/turntables/{started.json()['id']}"
            poll_until_done([client], path)
            redis.stop()
            down = [client.post("/v1/meshes", content=mesh_bytes("ply")),
                    client.post("/v1/turntables", json={**body, "frames": 4}),
                    client.get(path), client.get(path + "/result")]
            for answer in down:
                assert answer.status_code == 503, (answer.request.url, answer.text)
                assert answer.json()["error"] == "store_unavailable", answer.text
                assert int(answer.headers["retry-after"]) >= 1
            renders = [client.get(url(mu_f=5 + i / 10, width=48, height=48)).status_code
                       for i in range(6)]
            assert renders == [200] * 6
            redis.start()
            upload = client.post("/v1/meshes", content=mesh_bytes("ply"))
            assert upload.status_code == 201, upload.text
            mesh = [client.get(f"/v1/render?preset={PRESET}&mesh={upload.json()['id']}"
                               f"&mu_f={3 + i / 7}&width=48&height=48&quality=draft")
                    for i in range(4)]
            assert [m.status_code for m in mesh] == [200] * 4
            again = client.post("/v1/turntables", json={**body, "frames": 4})
            assert again.status_code == 202, again.text
    print(f"\nstore down: {[a.status_code for a in down]} for upload, turntable start, poll "
          f"and result, each with Retry-After; plain renders {renders}; back: upload 201, "
          f"its renders {[m.status_code for m in mesh]}, turntable 202")


class VaryingUpstream(BaseHTTPRequestHandler):
    """An upstream whose answer depends on Accept and says so (Vary), as format=auto does."""

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        body = f"made for {self.headers.get('Accept')}".encode()
        self.send_response(200)
        for name, value in (("Content-Type", "text/plain"), ("Vary", "Accept"),
                            ("Cache-Control", "public, max-age=60"),
                            ("Content-Length", str(len(body)))):
            self.send_header(name, value)
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: object) -> None:
        pass


def test_the_cache_keeps_one_variant_per_accept():
    """Vary: Accept is honoured: each Accept gets its own answer, each cached apart."""
    need_nginx()
    server = ThreadingHTTPServer(("127.0.0.1", 0), VaryingUpstream)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        with (LocalProxy([f"http://127.0.0.1:{server.server_port}"]) as proxy,
              httpx.Client(base_url=proxy.base, trust_env=False) as client):
            seen = []
            for accept in ("image/avif", "image/png", "image/avif", "image/png"):
                answer = client.get("/v1/render?x=1", headers={"Accept": accept})
                assert answer.text == f"made for {accept}"
                seen.append(answer.headers["x-cache-status"])
        assert seen == ["MISS", "MISS", "HIT", "HIT"]
    finally:
        server.shutdown()
        server.server_close()
