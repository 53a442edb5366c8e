"""Environment light's cost as same-run ratios, against issue 21's targets.

    python bench/speed_env.py [--rounds 7] [--per-round 8] [--presets sphere cd-rom]

Per preset, in process (a warm ``Renderer`` + PNG encode, 256², as bench/speed.py's
in-process rows), one image of each variant after one floor image (bench/floor/floor.py),
again and again, so every variant and the floor see the same load:

- ``key``: the preset's own lights (its key light), standard and draft;
- ``env``: ``environment=studio`` read from the map by lobe sampling
  (gl/environment_light.py), standard and draft at their tiers' ``environment_samples``;
- standard with ``environment_samples`` 1, 2, 8 beside the tier's own: a straight line
  through the four splits the render into a part per lobe sample and a fixed part;
- on the sphere and cd-rom, standard at 8 wavelengths (the tier's 16 halved), key
  light and environment: how much of a lobe sample is the spectral BRDF it evaluates;
- on the sphere, ``environment_lights=16`` (standard's K): the median-cut path, for
  comparison.

Each round keeps its medians; the figure reported is the median over rounds. The
ratio to the key light pairs the two variants round by round (median of the rounds'
ratios); the ratio to the floor is to the floor's median over the whole run, as in
bench/speed.py. Targets: ``env standard`` ≤ 1.5× ``key standard`` of the same preset,
``env draft`` ≤ 3× the floor; each is stated with its margin (aim: 20 % inside).
Prints the table, writes bench/results/speed_env.{json,md}.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time

from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve
from opaline.model.tiers import TIERS
from report import save  # bench/report.py: run from bench/, it is on the path
from speed import FLOOR, SIZE, Child

PRESETS = ("sphere", "nacre-film", "oil-film", "soap-bubble", "cd-rom", "cd-rom-grating",
           "dvd-grating", "cd-rom-ashikhmin")
ENVIRONMENT = "studio"
TARGETS = {"standard_over_key": 1.5, "draft_over_floor": 3.0}
AIM = 0.2  # the margin aimed for: 20 % inside each target
SWEEP = (1, 2, 8)  # environment_samples beside the standard tier's own
COMPARE_K = TIERS["standard"].environment_lights
WAVELENGTH_PRESETS = ("sphere", "cd-rom")


def variants(preset: str) -> list[tuple[str, dict]]:
    """(label, request fields) of every image measured on ``preset``."""
    env = {"environment": ENVIRONMENT}
    rows = [("key standard", {"quality": "standard"}), ("key draft", {"quality": "draft"}),
            ("env standard", {"quality": "standard", **env}),
            ("env draft", {"quality": "draft", **env})]
    rows += [(f"env standard samples={n}",
              {"quality": "standard", **env, "environment_samples": n}) for n in SWEEP]
    if preset in WAVELENGTH_PRESETS:  # how much of a lobe sample is the spectral BRDF
        rows += [(f"{kind} standard wavelengths=8",
                  {"quality": "standard", **extra, "wavelengths": 8})
                 for kind, extra in (("key", {}), ("env", env))]
    if preset == "sphere":
        rows.append((f"env standard K={COMPARE_K}",
                     {"quality": "standard", **env, "environment_lights": COMPARE_K}))
    return rows


def serve_in_process() -> None:
    """Child: a JSON line ``{"preset": ..., fields ...}`` → seconds of one warm render + PNG."""
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve
    from opaline.output.encode import encode_frame

    renderer = Renderer()
    jobs: dict[str, object] = {}
    for line in sys.stdin:
        if line not in jobs:  # compile and upload outside the timing
            fields = json.loads(line)
            jobs[line] = resolve(RenderRequest(**fields, width=SIZE, height=SIZE),
                                 get_preset(fields["preset"]))
            renderer.render(jobs[line])
        job = jobs[line]
        start = time.perf_counter()
        encode_frame(renderer.render(job), job.format)
        print(json.dumps([time.perf_counter() - start]), flush=True)


def measure(args) -> dict:
    load_before = os.getloadavg()[0]
    floor = Child([sys.executable, str(FLOOR), "--serve"])
    local = Child([sys.executable, __file__, "--child"])
    lines = {preset: [(label, json.dumps({"preset": preset, **fields}))
                      for label, fields in variants(preset)] for preset in args.presets}
    for group in lines.values():  # warm-up: compile every variant
        for _, line in group:
            local.ask(line)
    floors: list[list[float]] = []
    rounds: dict[tuple[str, str], list[list[float]]] = {}
    for _ in range(args.rounds):
        for preset, group in lines.items():
            round_floor: list[float] = []
            round_times: dict[str, list[float]] = {label: [] for label, _ in group}
            for _ in range(args.per_round):
                round_floor += floor.ask("1")
                for label, line in group:
                    round_times[label] += local.ask(line)
            floors.append(round_floor)
            for label, times in round_times.items():
                rounds.setdefault((preset, label), []).append(times)
    floor.close()
    local.close()
    floor_s = statistics.median(statistics.median(r) for r in floors)
    rows = []
    for (preset, label), found in rounds.items():
        medians = [statistics.median(r) for r in found]
        keys = [statistics.median(r) for r in rounds[(preset, f"key {label.split()[1]}")]]
        rows.append({"preset": preset, "variant": label, "ms": 1e3 * statistics.median(medians),
                     "over_floor": statistics.median(medians) / floor_s,
                     "over_key": statistics.median(m / k for m, k in zip(medians, keys, strict=True))})
    return {"floor_ms": 1e3 * floor_s, "rows": rows, "verdicts": verdicts(rows),
            "per_sample": per_sample(rows),
            "environment": ENVIRONMENT, "rounds": args.rounds, "per_round": args.per_round,
            "load_average": [load_before, os.getloadavg()[0]]}


def verdicts(rows: list[dict]) -> list[dict]:
    """Each preset's two targets: the figure, the target, and how far inside it (negative:
    missed by that much)."""
    found = []
    for row in rows:
        if row["variant"] == "env standard":
            figure, target, what = row["over_key"], TARGETS["standard_over_key"], "× key standard"
        elif row["variant"] == "env draft":
            figure, target, what = row["over_floor"], TARGETS["draft_over_floor"], "× floor"
        else:
            continue
        margin = 1.0 - figure / target
        found.append({"preset": row["preset"], "variant": row["variant"], "figure": figure,
                      "target": target, "unit": what, "margin": margin,
                      "passes": margin >= 0.0, "aim_met": margin >= AIM})
    return found


def per_sample(rows: list[dict]) -> list[dict]:
    """Least-squares line through each preset's standard renders at 1, 2, 4 and 8 lobe
    samples: ms per sample (the lobe's sampling, map read and BRDF per sample), the
    fixed part (the rest of the shader, the pass, readback, PNG) and the key light."""
    found = []
    for preset in dict.fromkeys(row["preset"] for row in rows):
        mine = {row["variant"]: row["ms"] for row in rows if row["preset"] == preset}
        points = [(n, mine[f"env standard samples={n}"]) for n in SWEEP]
        points.append((standard_samples(preset), mine["env standard"]))
        slope, fixed = statistics.linear_regression(*zip(*points, strict=True))
        found.append({"preset": preset, "ms_per_sample": slope, "fixed_ms": fixed,
                      "key_standard_ms": mine["key standard"],
                      "standard_samples": standard_samples(preset)})
    return found


def standard_samples(preset: str) -> int:
    """The standard tier's lobe samples (a grating's: reads) under the environment on
    ``preset``: the rotation source's and a grating's are their own (model/tiers.py)."""
    request = RenderRequest(preset=preset, quality="standard", environment=ENVIRONMENT)
    return resolve(request, get_preset(preset)).environment_sample_count


def share(fit: dict) -> float:
    """The lobe samples' part of the line's value at the standard tier's sample count."""
    sampled = fit["standard_samples"] * fit["ms_per_sample"]
    return sampled / (sampled + fit["fixed_ms"])


def markdown(result: dict) -> str:
    lines = [f"Environment `{result['environment']}`, 256², in process (warm render + PNG). "
             f"Floor (bare GL): {result['floor_ms']:.2f} ms, median of {result['rounds']} "
             f"rounds of {result['per_round']} alternated images; 1-minute load average "
             f"{result['load_average'][0]:.1f} before, {result['load_average'][1]:.1f} after "
             f"(2 cores). Command: `python bench/speed_env.py`.", "",
             "| preset | variant | ms | × floor | × key light, same tier |",
             "|---|---|---|---|---|"]
    for row in result["rows"]:
        lines.append(f"| {row['preset']} | {row['variant']} | {row['ms']:.1f} | "
                     f"{row['over_floor']:.2f} | {row['over_key']:.2f} |")
    lines += ["", f"Targets (issue 21; aim {AIM:.0%} inside):", "",
              "| preset | measure | figure | target | margin | verdict |", "|---|---|---|---|---|---|"]
    for v in result["verdicts"]:
        verdict = ("pass" if v["aim_met"] else "pass, inside by less than the aim") \
            if v["passes"] else f"MISSED by {-v['margin']:.0%}"
        lines.append(f"| {v['preset']} | {v['variant']} {v['unit']} | {v['figure']:.2f} | "
                     f"≤ {v['target']:g} | {v['margin']:+.0%} | {verdict} |")
    lines += ["", f"Standard at {list(SWEEP)} lobe samples (a grating: reads) and at the tier's "
              "own, a straight line through them (ms; nothing to fit where the environment is "
              "lights):", "",
              "| preset | per lobe sample | fixed | key light standard | tier's samples | "
              "samples' share there |",
              "|---|---|---|---|---|---|"]
    for p in result["per_sample"]:
        lines.append(f"| {p['preset']} | {p['ms_per_sample']:.2f} | {p['fixed_ms']:.1f} | "
                     f"{p['key_standard_ms']:.1f} | {p['standard_samples']} | "
                     f"{share(p):.0%} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--per-round", type=int, default=8)
    parser.add_argument("--presets", nargs="+", default=list(PRESETS))
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        serve_in_process()
        return
    result = measure(args)
    save("speed_env", result, markdown(result))


if __name__ == "__main__":
    main()
