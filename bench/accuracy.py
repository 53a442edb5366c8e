"""The speed/accuracy trade, measured over the whole space (docs/design.md §8).

    python bench/accuracy.py [--size 128] [--presets cd-rom ...] [--write-table]
    python bench/accuracy.py --from-results [--write-table]   # tables and plot again
    python bench/accuracy.py --presets morpho --merge [--write-table]   # one preset again
    python bench/accuracy.py --from-results --time-tiers [--presets oil-film ...]
    python bench/accuracy.py --presets cd-rom-grating --merge-table   # the table only

Per preset, a grid over samples × wavelengths × anti-aliasing (accuracy_grid.py),
each point timed (fastest of 3 warm renders) and scored against the converged
spectrum: FLIP and CIEDE2000 (metrics.py), and for the RGB model its sampling
error against the RGB model converged. Harder variants of each preset's material
are scored too (model/auto.py). References are cached under
bench/results/references/; the raw rows go to bench/results/accuracy_grid.json.

Writes docs/accuracy.md (accuracy_report.py; the hand-written GUIDE section is
kept), docs/accuracy.csv, docs/accuracy.png (accuracy_plot.py), and with
--write-table the table quality=auto reads, service/opaline/model/quality_table.json.
--merge measures only the named presets and keeps every other preset's rows from the last
run. --merge-table, where that run's raw results are not at hand (they are not committed),
measures the named presets and puts their entries into the shipped table, keeping the
others'; docs/accuracy.* are left as they are. Either is valid only for the presets whose
entries still describe what renders: each entry is stamped with its preset's hash and with
the program variants its measurement compiled (references included), hashed as they
compile (gl/variant_source.py: comments and branches they skip do not count), and
tests/model/test_auto.py names every preset whose stamp no longer matches. A change in
Python that the stamps do not see is what bench/unchanged_renders.py --base REV shows.
Every entry ranks its points by a cost model fitted to their measured times (fit_times),
in a merge as in a full run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# Runnable as a script from a checkout: the bench's modules and the service package.
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from accuracy_grid import Bench, measure, measured_programs, paired_ratios  # noqa: E402
from accuracy_merge import RAW, last_run, merged  # noqa: E402
from opaline.gl.variant_source import variant_digest, variant_label  # noqa: E402
from opaline.output.files import write_atomic  # noqa: E402

DOCS = ROOT / "docs"


def machine(bench: Bench) -> dict[str, str]:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    gl = bench.renderer.gl.describe()
    return {"platform": platform.platform(), "cpu": f"{cpu} ({os.cpu_count()} cores)",
            "gl": f"{gl['renderer']}, {gl['version']} ({gl['backend']})",
            "python": platform.python_version()}


def invocation() -> dict[str, str]:
    """This run's command line and start, as the report cites them."""
    return {"command": " ".join(["python bench/accuracy.py", *sys.argv[1:]]),
            "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")}


def run(names: list[str], size: int, variants: list[str], tiers: bool = True) -> dict:
    """The grid's rows and facts for ``names``, and (``tiers``) each tier's time over draft."""
    from opaline.model.presets import all_presets

    presets = all_presets()
    started = time.perf_counter()
    bench = Bench(size)
    info = {**machine(bench), "size": size, "load": [os.getloadavg()[0]], **invocation(),
            "programs": {}, "compiled": {}}
    rows, facts = [], []
    try:
        for name in names:
            t0 = time.perf_counter()
            base_rows, base = measure(bench, presets[name], "base", None)
            rows += base_rows
            facts.append(base["facts"])
            for variant in variants:
                more, found = measure(bench, presets[name], variant, base["times"])
                rows += more
                facts.append(found["facts"])
            programs = measured_programs(bench, presets[name], variants)
            # As the table lists them (one spelling, the raw results' and the table's).
            info["programs"][name] = [variant_label(key) for key in programs]
            # Hashed now, from the sources just measured: written later (--merge,
            # --from-results), an entry would carry the digest of sources edited since.
            info["compiled"][name] = variant_digest(programs)
            print(f"{name}: {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
        ratios = time_tiers(bench, names) if tiers else {}
    finally:
        bench.release()
    info["wall_s"] = time.perf_counter() - started
    info["load"].append(os.getloadavg()[0])
    return {"info": info, "rows": rows, "facts": facts, "tier_ratios": ratios}


# The tier that draft replaced (one RGB sample, analytic AA), timed against draft too.
OLD_DRAFT = (1, 0, "analytic")


def time_tiers(bench: Bench, names: list[str]) -> dict[str, dict[str, float]]:
    """Per preset, each tier's (and the old draft's) time over draft's, in alternating pairs."""
    from accuracy_front import tier_setting
    from opaline.model.presets import all_presets

    out = {}
    for name in names:
        points = {"old draft": OLD_DRAFT, "standard": tier_setting(name, "standard"),
                  "high": tier_setting(name, "high")}
        # A film's draft and standard may be one setting (the fast path): time it once.
        found = paired_ratios(bench, all_presets()[name], list(dict.fromkeys(points.values())),
                              tier_setting(name, "draft"), pairs=7)
        out[name] = {label: found[point] for label, point in points.items()}
        print(f"{name}: {out[name]}", file=sys.stderr, flush=True)
    return out


def main() -> None:
    from opaline.model.auto import TABLE_PATH, VARIANTS

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--presets", nargs="+", help="default: every preset")
    parser.add_argument("--base-only", action="store_true",
                        help="only each preset's own material (no table variants)")
    parser.add_argument("--from-results", action="store_true",
                        help=f"re-write the outputs from {RAW.relative_to(ROOT)}")
    parser.add_argument("--time-tiers", action="store_true",
                        help="with --from-results: time the tiers against draft again "
                             "(with --presets: those presets' only)")
    parser.add_argument("--merge", action="store_true",
                        help="with --presets: replace those presets' rows in the last run's "
                             "results and keep the others'")
    parser.add_argument("--merge-table", action="store_true",
                        help="with --presets: measure them and replace only their entries in "
                             "the shipped table (see bench/unchanged_renders.py)")
    parser.add_argument("--write-table", action="store_true",
                        help=f"also write {TABLE_PATH.relative_to(ROOT)}")
    parser.add_argument("--out", type=Path, default=DOCS, help="where accuracy.* go")
    args = parser.parse_args()

    from opaline.model.presets import all_presets

    if args.merge_table:
        merge_table(parser, args)
        return
    if args.from_results:
        data = json.loads(RAW.read_text())
        if args.time_tiers:
            bench = Bench(data["info"]["size"])
            stamp, started = invocation(), time.perf_counter()
            try:
                names = args.presets or list(dict.fromkeys(r["preset"] for r in data["rows"]))
                data["tier_ratios"] = {**data.get("tier_ratios", {}),
                                       **time_tiers(bench, names)}
            finally:
                bench.release()
            data["info"].setdefault("retimed", []).append(
                {**stamp, "wall_s": time.perf_counter() - started})
            write_atomic(RAW, json.dumps(data, indent=1).encode())
    else:
        names = args.presets or list(all_presets())
        unknown = [n for n in names if n not in all_presets()]
        if unknown:
            parser.error(f"unknown presets {unknown}; known: {', '.join(all_presets())}")
        last = last_run(parser, args) if args.merge else None
        data = run(names, args.size, [] if args.base_only else list(VARIANTS[1:]))
        if last is not None:
            data = merged(last, data, names)
        write_atomic(RAW, json.dumps(data, indent=1).encode())
    write_outputs(data, args.out, args.write_table)


def merge_table(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Measure ``args.presets`` and put their entries into the shipped table."""
    from accuracy_grid import fit_times
    from accuracy_table import merged_table
    from opaline.model.auto import TABLE_PATH, VARIANTS

    if not args.presets:
        parser.error("--merge-table needs --presets: the presets to measure again")
    shipped = json.loads(TABLE_PATH.read_text())
    if shipped["size"] != args.size:
        parser.error(f"--merge-table: the table is at {shipped['size']}², "
                     f"this run would be at {args.size}²")
    data = run(args.presets, args.size, list(VARIANTS[1:]), tiers=False)  # the table has none
    # Ranked by the cost model fitted to their times, as a full run's entries are
    # (write_outputs): one point's fastest-of-3 scatters by 10-50 % on a shared machine.
    data["info"]["time_model"] = fit_times(data["rows"])
    write_atomic(TABLE_PATH, merged_table(shipped, data["rows"], data["facts"], data["info"]))
    print(f"{', '.join(args.presets)}: measured in {data['info']['wall_s']:.0f} s; "
          f"their entries in {TABLE_PATH.relative_to(ROOT)} replaced")


def write_outputs(data: dict, out: Path, table: bool) -> None:
    from accuracy_csv import to_csv
    from accuracy_grid import fit_times
    from accuracy_plot import plot
    from accuracy_report import kept_guide, to_markdown
    from accuracy_table import quality_table
    from opaline.model.auto import TABLE_PATH

    rows, facts, info = data["rows"], data["facts"], data["info"]
    info["time_model"] = fit_times(rows)
    info["tier_ratios"] = data.get("tier_ratios", {})
    markdown = to_markdown(rows, facts, info, kept_guide(out / "accuracy.md"))
    write_atomic(out / "accuracy.csv", to_csv(rows, info))
    write_atomic(out / "accuracy.png", plot(rows, info))
    write_atomic(out / "accuracy.md", markdown.encode())
    if table:
        write_atomic(TABLE_PATH, quality_table(rows, facts, info))
    print(markdown)


if __name__ == "__main__":
    main()
