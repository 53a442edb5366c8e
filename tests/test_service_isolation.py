"""A real `opaline serve` that one client cannot knock over: the event loop stays responsive,
memory stays under the documented budget, hung or killed workers are replaced."""

from __future__ import annotations

import os
import signal
import statistics
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from opaline.server.localserver import LocalServer, loopback_env

pytestmark = pytest.mark.gl
OPENER = urllib.request.build_opener(urllib.request.ProxyHandler({}))


def get(url: str, timeout: float = 60.0) -> tuple[int, bytes, dict[str, str], float]:
    start = time.perf_counter()
    try:
        with OPENER.open(url, timeout=timeout) as answer:
            return answer.status, answer.read(), dict(answer.headers), time.perf_counter() - start
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read(), dict(exc.headers), time.perf_counter() - start


def descendants(pid: int) -> list[int]:
    """Every process whose ancestry reaches ``pid``, read from /proc."""
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(stat.parent.name)] = int(fields[1])
    found, frontier = [], [pid]
    while frontier:
        parent = frontier.pop()
        children = [p for p, pp in parents.items() if pp == parent]
        found += children
        frontier += children
    return found


def rss(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, IndexError):
        return 0


def worker_pids(base: str) -> list[int]:
    import json

    return [w["pid"] for w in json.loads(get(base + "/readyz")[1])["workers"] if w["pid"]]


@pytest.fixture
def env(backend) -> dict[str, str]:
    return {"OPALINE_GL_BACKEND": backend, "OPALINE_WARMUP": "0", "OPALINE_CALIBRATE": "0"}


def test_healthz_stays_fast_during_a_huge_render(env):
    """/healthz p99 < 100 ms while a worker draws a 2048² × 128-wavelength MDF plot."""
    with LocalServer(env={**env, "OPALINE_DEADLINE_S": "300",
                          "OPALINE_RENDER_TIMEOUT_S": "300"}) as server:
        answers: list = []
        big = threading.Thread(target=lambda: answers.append(
            get(server.base + "/v1/mdf?size=2048&wavelengths=128", timeout=300)))
        big.start()
        time.sleep(0.3)
        latencies = []
        while big.is_alive() and len(latencies) < 400:
            status, _, _, seconds = get(server.base + "/healthz", timeout=5)
            assert status == 200
            latencies.append(seconds)
            time.sleep(0.01)
        big.join(300)
        assert answers and answers[0][0] == 200
        assert len(latencies) >= 20, "the render was too short to measure anything"
        p99 = statistics.quantiles(latencies, n=100)[98]
        print(f"\n/healthz during the render: {len(latencies)} probes, p50 "
              f"{statistics.median(latencies) * 1e3:.1f} ms, p99 {p99 * 1e3:.1f} ms, render "
              f"{answers[0][3]:.1f} s")
        assert p99 < 0.1


def test_hung_and_killed_workers_are_replaced(env):
    """A stopped worker: 503 within the limit plus a second, then a new worker renders;
    a worker killed with SIGKILL is survived the same way."""
    with LocalServer(env={**env, "OPALINE_RENDER_TIMEOUT_S": "2"}) as server:
        url = server.base + "/v1/render?width=64&height=64&quality=draft"
        [pid] = worker_pids(server.base)
        os.kill(pid, signal.SIGSTOP)
        status, body, headers, seconds = get(url + "&mu_f=1")
        assert status == 503 and "retry-after" in {k.lower() for k in headers} and b"limit" in body
        assert seconds < 2 + 1
        assert get(url + "&mu_f=2")[0] == 200
        [replacement] = worker_pids(server.base)
        assert replacement != pid
        os.kill(replacement, signal.SIGKILL)
        time.sleep(0.5)
        assert get(url + "&mu_f=3")[0] == 200
        metrics = get(server.base + "/metrics")[1].decode()
        assert 'opaline_worker_restarts_total{reason="watchdog"} 1.0' in metrics
        assert 'opaline_worker_restarts_total{reason="died"} 1.0' in metrics


def test_admission_refuses_at_once_and_keeps_small_requests_on_time(env):
    """A request predicted past the deadline is refused in under 50 ms; a small request
    behind a big one answers within its deadline."""
    deadline = 6.0
    with LocalServer(env={**env, "OPALINE_DEADLINE_S": str(deadline)}) as server:
        get(server.base + "/v1/render?width=64&height=64&quality=draft")  # warm
        # Within the cost budget (RGB), but far over the deadline when predicted.
        slow = server.base + "/v1/render?width=2048&height=2048&samples=64&wavelengths=0"
        refusals = [get(slow) for _ in range(5)]
        assert all(r[0] == 422 and b"predicted" in r[1] for r in refusals)
        print(f"\nrefusal times: {[round(r[3] * 1e3, 1) for r in refusals]} ms")
        assert statistics.median(r[3] for r in refusals) < 0.05
        big = threading.Thread(target=get, args=(
            server.base + "/v1/render?width=1024&height=1024&samples=4&wavelengths=8",))
        big.start()
        time.sleep(0.2)
        status, _, headers, seconds = get(server.base + "/v1/render?width=64&height=64"
                                          "&quality=draft&mu_f=3")
        big.join(60)
        assert seconds < deadline + 1
        assert status == 200 or (status == 503 and "retry-after" in {k.lower() for k in headers})


def test_a_flood_of_variants_and_big_targets_stays_under_the_memory_budget(env):
    """300 requests, each a new shader variant, many with 2048-pixel targets: the service and
    its workers together stay under the budget /readyz documents."""
    import json

    settings = {**env, "OPALINE_WORKER_PROGRAMS": "8", "OPALINE_WORKER_TARGET_MB": "256",
                "OPALINE_WORKER_MAX_RSS_MB": "600", "OPALINE_CACHE_BYTES": str(32 << 20),
                "OPALINE_QUEUE_SIZE": "4", "OPALINE_DEADLINE_S": "30"}
    with LocalServer(env=settings) as server:
        budget = json.loads(get(server.base + "/readyz")[1])["memory_budget_bytes"]
        peak, statuses = 0, []
        lock = threading.Lock()

        def ask(i: int) -> None:
            wavelengths = 4 + i % 125
            mdf = ("multipeak", "ashikhmin")[i // 125 % 2]
            size = "width=2048&height=2048" if i % 30 == 0 else f"width=2048&height={16 + i}"
            status = get(f"{server.base}/v1/render?{size}&samples=1&wavelengths={wavelengths}"
                         f"&mdf={mdf}&aa=none", timeout=120)[0]
            with lock:
                statuses.append(status)

        threads = [threading.Thread(target=lambda k=k: [ask(i) for i in range(k, 300, 4)])
                   for k in range(4)]
        for thread in threads:
            thread.start()
        while any(t.is_alive() for t in threads):
            pids = [server.proc.pid, *descendants(server.proc.pid)]
            peak = max(peak, sum(rss(pid) for pid in pids))
            time.sleep(0.1)
        assert len(statuses) == 300 and set(statuses) <= {200, 422, 503}
        assert statuses.count(200) >= 50
        print(f"\nflood: {statuses.count(200)} rendered, {statuses.count(503)} busy, "
              f"{statuses.count(422)} refused as too slow; "
              f"peak RSS {peak >> 20} MB of a {budget >> 20} MB budget")
        assert peak < budget


def test_sigkill_of_a_batch_leaves_no_process_behind(tmp_path, env):
    """SIGKILL of `opaline batch --jobs 2` mid-render: every worker is gone within 5 s."""
    materials = tmp_path / "materials"
    materials.mkdir()
    for i in range(6):
        (materials / f"m{i}.toml").write_text(
            f'preset = "cd-rom"\nwidth = 1024\nheight = 1024\nsamples = 64\nwavelengths = 0\n'
            f'mu_f = {i + 1}\n')
    batch = subprocess.Popen([sys.executable, "-m", "opaline.cli.main", "batch", str(materials),
                              "--out", str(tmp_path / "out"), "--jobs", "2"],
                             env=loopback_env(**env), stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    end = time.monotonic() + 60
    while len(descendants(batch.pid)) < 2:
        assert time.monotonic() < end and batch.poll() is None, "no workers started"
        time.sleep(0.1)
    time.sleep(1.0)
    workers = descendants(batch.pid)
    batch.kill()
    batch.wait(5)
    end = time.monotonic() + 5
    while any(rss(pid) for pid in workers) and time.monotonic() < end:
        time.sleep(0.05)
    assert not any(Path(f"/proc/{pid}").exists() and rss(pid) for pid in workers)


def test_the_http_process_never_loads_gl(backend, tmp_path):
    """After start-up, a render and a GLSL export, the HTTP process has not imported
    moderngl or glcontext: only its worker processes touch GL."""
    script = tmp_path / "probe.py"
    script.write_text(
        "import sys\n"
        "from fastapi.testclient import TestClient\n"
        "from opaline.server.api import create_app\n"
        "from opaline.settings import Settings\n"
        "if __name__ == '__main__':\n"
        f"    app = create_app(Settings(gl_backend={backend!r}, calibrate=False))\n"
        "    with TestClient(app) as client:\n"
        "        assert client.get('/v1/render?width=32&height=32&quality=draft')"
        ".status_code == 200\n"
        "        assert client.get('/v1/export/glsl?mu_f=6').status_code == 200\n"
        "    print(sorted({'moderngl', 'glcontext'} & set(sys.modules)))\n")
    result = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                            timeout=120, env=loopback_env())
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == "[]"


def test_a_client_that_leaves_takes_its_queued_render_with_it(env):
    """A request whose client disconnects while it waits in the queue is dropped: the
    worker never renders it (counted as cancelled)."""
    import json
    import socket

    with LocalServer(env={**env, "OPALINE_DEADLINE_S": "300",
                          "OPALINE_RENDER_TIMEOUT_S": "300"}) as server:
        busy = threading.Thread(target=get, args=(
            server.base + "/v1/mdf?size=2048&wavelengths=128", 300))
        busy.start()
        time.sleep(0.5)
        with socket.create_connection(("127.0.0.1", server.port)) as sock:
            sock.sendall(b"GET /v1/render?width=64&height=64&quality=draft&mu_f=7 HTTP/1.1\r\n"
                         b"Host: 127.0.0.1\r\n\r\n")
            end = time.monotonic() + 5  # until it waits in the queue behind the plot
            while json.loads(get(server.base + "/readyz")[1])["queue_depth"] < 1:
                assert time.monotonic() < end, "the render never queued behind the plot"
                time.sleep(0.02)
        end = time.monotonic() + 10
        text = ""
        while time.monotonic() < end and "opaline_jobs_cancelled_total 1.0" not in text:
            text = get(server.base + "/metrics")[1].decode()
            time.sleep(0.1)
        busy.join(300)
        assert "opaline_jobs_cancelled_total 1.0" in text
        assert 'opaline_render_seconds_count{preset="sphere"}' not in text
