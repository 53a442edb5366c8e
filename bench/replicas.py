"""Replicas behind nginx against one replica, on loopback: what the shared cache buys.

    python bench/replicas.py                   # writes bench/results/replicas.{json,md}
    python bench/replicas.py --misses 60 --hits 2000

Three set-ups, each measured at 256² (cd-rom, standard tier) with the same
client load: one replica asked directly; one replica behind nginx (what the
proxy itself costs); two replicas behind nginx (deploy/nginx). For each:

- miss: distinct images (canonical URLs), so each request renders once;
- hit: one image asked for again and again (the replica's own cache when asked
  directly, nginx's shared cache behind the proxy);
- replica memory: peak resident memory of each replica's HTTP process and its
  render worker (VmHWM), after the load: what deploy/k8s requests.

On a 2-core machine two replicas cannot render faster than one (llvmpipe
already uses both cores); what scales is the hit path, which never reaches a
replica. Loopback only; every process is stopped at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
from contextlib import ExitStack
from pathlib import Path

import httpx

from http_load import SIZE, run_phase, summarise
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.server.canonical import canonical_job, canonical_url
from opaline.server.localproxy import LocalProxy
from opaline.server.localserver import LocalServer
from report import save  # bench/report.py: run from bench/, it is on the path

ENV = {"OPALINE_QUEUE_SIZE": "256", "OPALINE_DEADLINE_S": "120", "OPALINE_CALIBRATE": "0"}


def url(mu_f: float) -> str:
    request = RenderRequest(preset="cd-rom", width=SIZE, height=SIZE, mu_f=mu_f)
    preset = get_preset("cd-rom")
    job, query = canonical_job(resolve(request, preset), preset)
    return canonical_url(query, job.cache_key(preset.scene_key()))


def peak_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return round(int(line.split()[1]) / 1024, 1)
    return 0.0


def replica_memory(server: LocalServer) -> dict:
    workers = httpx.get(server.base + "/readyz", trust_env=False).json()["workers"]
    return {"http_mib": peak_mib(server.proc.pid),
            "workers_mib": [peak_mib(w["pid"]) for w in workers if w.get("pid")]}


def measure(setup: str, replicas: int, proxied: bool, misses: int, hits: int,
            concurrency: int, offset: float) -> tuple[list[dict], list[dict]]:
    with ExitStack() as stack:
        servers = [stack.enter_context(LocalServer(env=ENV)) for _ in range(replicas)]
        base = (stack.enter_context(LocalProxy([s.base for s in servers])).base if proxied
                else servers[0].base)
        client = stack.enter_context(httpx.Client(
            base_url=base, timeout=httpx.Timeout(120.0), trust_env=False,
            limits=httpx.Limits(max_connections=2 * concurrency)))
        hit_url = url(offset)
        for _ in range(2 * replicas):  # every replica compiles the variant before timing
            client.get(url(offset + 0.5 + _ / 1000)).raise_for_status()
        client.get(hit_url).raise_for_status()
        rows = []
        misses_urls = [url(offset + 1 + i * 0.001) for i in range(misses)]
        lat, wall, st = run_phase(client, misses_urls, concurrency)
        rows.append(summarise("miss", lat, wall, st, concurrency))
        lat, wall, st = run_phase(client, [hit_url] * hits, concurrency)
        rows.append(summarise("hit", lat, wall, st, concurrency))
        memory = [replica_memory(s) for s in servers]
    for row in rows:
        row["setup"] = setup
    return rows, memory


def median_row(rows: list[dict]) -> dict:
    """The round with the median throughput, with every round's range beside it."""
    ordered = sorted(rows, key=lambda r: r["throughput_rps"])
    row = dict(ordered[len(ordered) // 2])
    row["range_rps"] = [ordered[0]["throughput_rps"], ordered[-1]["throughput_rps"]]
    row["rounds"] = len(rows)
    return row


def table(rows: list[dict]) -> str:
    lines = ["| set-up | phase | clients | requests | non-200 | p50 ms | p95 ms | req/s "
             "(median [range]) |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['setup']} | {r['phase']} | {r['concurrency']} | {r['requests']} | "
                     f"{r['non_200']} | {r.get('p50_ms', '-')} | {r.get('p95_ms', '-')} | "
                     f"{r['throughput_rps']} [{r['range_rps'][0]}–{r['range_rps'][1]}] |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--misses", type=int, default=40)
    parser.add_argument("--hits", type=int, default=1500)
    parser.add_argument("--concurrency", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=3,
                        help="rounds; the set-ups take turns, so a busy moment of the "
                             "machine does not fall on one set-up only")
    args = parser.parse_args(argv)
    runs: dict[tuple[str, str], list[dict]] = {}
    memory: dict[str, list[dict]] = {}
    setups = [("1 replica", 1, False), ("nginx + 1 replica", 1, True),
              ("nginx + 2 replicas", 2, True)]
    for round_ in range(args.repeat):
        for index, (setup, replicas, proxied) in enumerate(setups[round_ % 3:] +
                                                           setups[:round_ % 3]):
            got, memory[setup] = measure(setup, replicas, proxied, args.misses, args.hits,
                                         args.concurrency, offset=100.0 * round_ + 10 * index)
            for row in got:
                runs.setdefault((setup, row["phase"]), []).append(row)
                print(json.dumps(row), flush=True)
    rows = [median_row(runs[(setup, phase)]) for setup, _, _ in setups
            for phase in ("miss", "hit")]
    base = {r["phase"]: r["throughput_rps"] for r in rows if r["setup"] == "1 replica"}
    ratios = {f"{r['setup']} {r['phase']}": round(r["throughput_rps"] / base[r["phase"]], 2)
              for r in rows if base.get(r["phase"])}
    result = {"machine": {"cpus": os.cpu_count(), "python": sys.version.split()[0],
                          "platform": platform.platform()},
              "size": SIZE, "rows": rows, "ratios_vs_1_replica": ratios,
              "replica_peak_memory": memory}
    text = (f"# Replicas behind nginx ({SIZE}², cd-rom, standard; {os.cpu_count()} cores)\n\n"
            f"`python bench/replicas.py --misses {args.misses} --hits {args.hits} "
            f"--concurrency {args.concurrency} --repeat {args.repeat}`\n\n{table(rows)}\n\n"
            f"Throughput against one replica asked directly: {json.dumps(ratios)}\n\n"
            f"Peak memory per replica (MiB): {json.dumps(memory)}\n")
    save("replicas", result, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
