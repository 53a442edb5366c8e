"""Opaline's speed as ratios to a bare-GL floor measured in the same run.

    python bench/speed.py [--rounds 5] [--per-round 8] [--clients 4]

The floor (bench/floor/floor.py) draws a ~4k-triangle Blinn-Phong sphere,
reads RGBA8 back and writes a PNG at zlib level 1: the least a 256² image can
cost here. Every figure is measured in rounds that alternate floor and
Opaline image by image (A, B, A, B ...), each round's median kept, and the
median over rounds reported, so a machine shared with other work moves both
alike. Ratios are to the floor's median over the whole run:

- in-process render + PNG per preset and tier (a warm ``Renderer``);
- HTTP cache miss per preset (draft) and tier (sphere), one client over
  loopback to ``opaline serve`` with one worker, and where its time goes: the
  HTTP exchange (client time less Server-Timing total), the route's own
  (total less render), and the wait for the worker (render) less the
  in-process time of the same image: the hand-off;
- HTTP cache hit: client time, and the server's own from Server-Timing;
- cold ``opaline render sphere --quality draft`` against the cold floor script;
- throughput: N clients asking for distinct draft spheres at once.

Prints a table, writes bench/results/speed.{json,md}.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from itertools import count
from pathlib import Path

from report import save  # bench/report.py: run from bench/, it is on the path

ROOT = Path(__file__).resolve().parent.parent
FLOOR = ROOT / "bench" / "floor" / "floor.py"
SIZE = 256
TIMING = re.compile(r"total;dur=([\d.]+)")
RENDER_TIMING = re.compile(r"render;dur=([\d.]+)")
_unique = count(1)


class Child:
    """A process answering one JSON line per request line (the floor, or Opaline's renderer)."""

    def __init__(self, argv: list[str]) -> None:
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True, cwd=ROOT)

    def ask(self, line: str) -> list[float]:
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait(timeout=30)


def serve_in_process() -> None:
    """Child: ``PRESET QUALITY N`` → seconds of N warm renders + PNG encodes."""
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve
    from opaline.output.encode import encode_frame

    renderer = Renderer()
    warm: set[str] = set()
    for line in sys.stdin:
        name, quality, n = line.split()
        job = resolve(RenderRequest(preset=name, quality=quality, width=SIZE, height=SIZE),
                      get_preset(name))
        if line not in warm:  # compile and upload outside the timing
            renderer.render(job)
            warm.add(line)
        times = []
        for _ in range(int(n)):
            start = time.perf_counter()
            encode_frame(renderer.render(job), job.format)
            times.append(time.perf_counter() - start)
        print(json.dumps(times), flush=True)


def http_miss(client, base: str, preset: str, quality: str,
              server: list[tuple[float, float]] | None = None) -> float:
    """One render nobody asked for before: a fresh exposure makes a fresh cache key.
    ``server`` gets Server-Timing's (total, render) in seconds."""
    exposure = 1.0 + next(_unique) * 1e-6
    start = time.perf_counter()
    answer = client.get(f"{base}/v1/render", params={
        "preset": preset, "quality": quality, "width": SIZE, "height": SIZE,
        "exposure": exposure})
    elapsed = time.perf_counter() - start
    answer.raise_for_status()
    if server is not None:
        timing = answer.headers["server-timing"]
        server.append((float(TIMING.search(timing)[1]) / 1e3,
                       float(RENDER_TIMING.search(timing)[1]) / 1e3))
    return elapsed


def median_of_rounds(rounds: list[list[float]]) -> float:
    return statistics.median(statistics.median(r) for r in rounds)


def cold(rounds: int) -> dict:
    """Cold processes, alternated: the floor script, then ``opaline render``.

    Measured as a user meets them: with bytecode written and read (an installed package
    has its .pyc; PYTHONDONTWRITEBYTECODE would recompile every module each time), and
    after one untimed run of each, which writes that bytecode and Mesa's shader cache."""
    out = Path(tempfile.mkdtemp())
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    commands = (([sys.executable, str(FLOOR), "--once", str(out / "f.png")], []),
                ([sys.executable, "-m", "opaline", "render", "sphere", "--quality", "draft",
                  "-o", str(out / "o.png")], []))
    for argv, _ in commands:
        subprocess.run(argv, check=True, cwd=ROOT, capture_output=True, env=env)
    for _ in range(rounds):
        for argv, times in commands:
            start = time.perf_counter()
            subprocess.run(argv, check=True, cwd=ROOT, capture_output=True, env=env)
            times.append(time.perf_counter() - start)
    floor, opaline = (statistics.median(times) for _, times in commands)
    return {"floor_ms": 1e3 * floor, "opaline_ms": 1e3 * opaline, "ratio": opaline / floor}


def throughput(client_factory, base: str, clients: int, seconds: float) -> float:
    """Distinct draft spheres per second with ``clients`` asking at once."""
    deadline = time.perf_counter() + seconds

    def worker() -> int:
        done = 0
        with client_factory() as client:
            while time.perf_counter() < deadline:
                http_miss(client, base, "sphere", "draft")
                done += 1
        return done

    start = time.perf_counter()
    with ThreadPoolExecutor(clients) as pool:
        total = sum(pool.map(lambda _: worker(), range(clients)))
    return total / (time.perf_counter() - start)


def measure(args) -> dict:
    import httpx

    from opaline.model.presets import all_presets
    from opaline.server.localserver import LocalServer

    load_before = os.getloadavg()[0]
    floor = Child([sys.executable, str(FLOOR), "--serve"])
    local = Child([sys.executable, __file__, "--child"])
    presets = list(all_presets())
    items = [("in-process", p, "draft") for p in presets] + [("in-process", "sphere", "standard")]
    items += [("http-miss", p, "draft") for p in presets] + [("http-miss", "sphere", "standard")]
    samples: dict[str, list[list[float]]] = {"floor": []}
    timings: dict[str, list[tuple[float, float]]] = {}
    hits_client, hits_server = [], []
    env = {"OPALINE_CALIBRATE": "0", "OPALINE_QUEUE_SIZE": "64", "OPALINE_DEADLINE_S": "60"}
    with LocalServer(workers=args.workers, env=env) as server, \
            httpx.Client(timeout=60) as client:
        for item in items:  # warm-up: compile every variant in the worker and the child
            if item[0] == "in-process":
                local.ask(f"{item[1]} {item[2]} 1")
            else:
                http_miss(client, server.base, item[1], item[2])
        hit_url = f"{server.base}/v1/render?preset=sphere&quality=draft"
        client.get(hit_url).raise_for_status()
        for _ in range(args.rounds):
            for kind, preset, quality in items:
                # One floor image, one Opaline image, and again: both see the same load.
                floors, times = [], []
                for _ in range(args.per_round):
                    floors += floor.ask("1")
                    if kind == "in-process":
                        times += local.ask(f"{preset} {quality} 1")
                    else:
                        times.append(http_miss(client, server.base, preset, quality,
                                               timings.setdefault(f"{preset} {quality}", [])))
                samples["floor"].append(floors)
                samples.setdefault(f"{kind} {preset} {quality}", []).append(times)
            client_round, server_round = [], []
            for _ in range(args.per_round * 4):
                start = time.perf_counter()
                answer = client.get(hit_url)
                client_round.append(time.perf_counter() - start)
                server_round.append(float(TIMING.search(answer.headers["server-timing"])[1]))
            hits_client.append(client_round)
            hits_server.append(server_round)
        rps = throughput(lambda: httpx.Client(timeout=60), server.base, args.clients,
                         args.throughput_s)
    floor.close()
    local.close()
    floor_s = median_of_rounds(samples["floor"])
    rows = [{"measure": key, "ms": 1e3 * median_of_rounds(r), "ratio": median_of_rounds(r) / floor_s}
            for key, r in samples.items() if key != "floor"]
    return {"floor_ms": 1e3 * floor_s, "rows": rows, "http_split": http_split(samples, timings),
            "hit_client_ms": 1e3 * median_of_rounds(hits_client),
            "hit_server_ms": median_of_rounds(hits_server),
            "throughput": {"clients": args.clients, "workers": args.workers,
                           "images_per_s": rps, "floor_images_per_s": 1.0 / floor_s},
            "cold": cold(args.rounds), "rounds": args.rounds, "per_round": args.per_round,
            "load_average": [load_before, os.getloadavg()[0]]}


def http_split(samples: dict[str, list[list[float]]],
               timings: dict[str, list[tuple[float, float]]]) -> list[dict]:
    """Each HTTP miss's median time cut into: the exchange (client, loopback, uvicorn, the
    middleware before the route's first dependency), the route's own work, the hand-off
    to and from the worker, and the render + encode (the in-process median of the same
    image, measured in the same run)."""
    rows = []
    for key, found in timings.items():
        client = statistics.median(t for r in samples[f"http-miss {key}"] for t in r)
        inprocess = statistics.median(t for r in samples[f"in-process {key}"] for t in r)
        total = statistics.median(t for t, _ in found)
        render = statistics.median(r for _, r in found)
        rows.append({"case": key, "client_ms": 1e3 * client, "exchange_ms": 1e3 * (client - total),
                     "route_ms": 1e3 * (total - render), "handoff_ms": 1e3 * (render - inprocess),
                     "render_ms": 1e3 * inprocess})
    return rows


def markdown(result: dict) -> str:
    lines = [f"Floor (bare GL, 256² sphere, RGBA8 readback, PNG level 1): "
             f"{result['floor_ms']:.2f} ms, median of {result['rounds']} interleaved rounds "
             f"of {result['per_round']}; 1-minute load average {result['load_average'][0]:.1f} "
             f"before, {result['load_average'][1]:.1f} after (2 cores).", "",
             "| measure | preset | tier | ms | × floor |", "|---|---|---|---|---|"]
    for row in result["rows"]:
        kind, preset, tier = row["measure"].split()
        lines.append(f"| {kind} | {preset} | {tier} | {row['ms']:.1f} | {row['ratio']:.2f} |")
    lines += ["", "HTTP miss, where its time goes (ms; medians of every sample, so the parts "
              "need not add up exactly):", "",
              "| preset | tier | client | HTTP exchange | route | hand-off | render + encode |",
              "|---|---|---|---|---|---|---|"]
    for row in result["http_split"]:
        preset, tier = row["case"].split()
        lines.append(f"| {preset} | {tier} | {row['client_ms']:.1f} | {row['exchange_ms']:.2f} | "
                     f"{row['route_ms']:.2f} | {row['handoff_ms']:.2f} | {row['render_ms']:.1f} |")
    cold_ = result["cold"]
    tp = result["throughput"]
    lines += ["", f"- cache hit: {result['hit_client_ms']:.2f} ms at the client, "
              f"{result['hit_server_ms']:.2f} ms server time (Server-Timing total)",
              f"- cold `opaline render sphere --quality draft`: {cold_['opaline_ms']:.0f} ms vs "
              f"cold floor script {cold_['floor_ms']:.0f} ms: {cold_['ratio']:.2f}×",
              f"- throughput, {tp['clients']} clients, {tp['workers']} worker(s), draft sphere "
              f"misses: {tp['images_per_s']:.1f} images/s (floor, one process: "
              f"{tp['floor_images_per_s']:.1f}/s)"]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--per-round", type=int, default=8)
    parser.add_argument("--clients", type=int, default=4)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--throughput-s", type=float, default=5.0)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        serve_in_process()
        return
    result = measure(args)
    save("speed", result, markdown(result))


if __name__ == "__main__":
    main()
