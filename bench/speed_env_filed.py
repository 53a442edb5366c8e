"""Issue 21's speed target read against the day it was written: the studio at `standard`
now, over `standard` with its key light as the code drew it then and as it draws it now.

    python bench/speed_env_filed.py [--rounds 15] [--presets cd-rom-ashikhmin oil-film]
                                    [--filed 9eef867]

The issue asks the environment at `standard` (256²) to cost at most 1.5× "today's
`standard` with its key light". Since it was filed the key light's render got about twice
as fast (eq. 1's logarithm shared by the turned lobes, the discs' slivers, the packed
spectrum), so the same-run ratio of bench/speed_env.py compares the studio with a baseline
that moved. This measures both in one run: a worker process of the code at ``--filed``
(the last commit before the issue: a git worktree, made and removed here) and one of the
code checked out, each a warm renderer answering one render + PNG a line, alternated
round by round so that both see the same load. Ratios are each round's, then the median.
Prints the table, writes bench/results/speed_env_filed.{json,md}.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FILED = "9eef867"  # "snapshot: record a crash as the 500 a client sees", 2026-12-01
SIZE = 256
PER_ROUND = 8


def serve() -> None:
    """Child: a JSON line of request fields → the seconds of PER_ROUND warm renders + PNG.
    Only the API both commits share (the bench's own helpers are newer than the old one)."""
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve
    from opaline.output.encode import encode_frame

    renderer, warm = Renderer(), set()
    for line in sys.stdin:
        fields = json.loads(line)
        job = resolve(RenderRequest(**fields, width=SIZE, height=SIZE),
                      get_preset(fields["preset"]))
        if line not in warm:  # compile and upload outside the timing
            renderer.render(job)
            warm.add(line)
        times = []
        for _ in range(PER_ROUND):
            start = time.perf_counter()
            encode_frame(renderer.render(job), job.format)
            times.append(time.perf_counter() - start)
        print(json.dumps(times), flush=True)


class Worker:
    def __init__(self, root: Path) -> None:
        env = {**os.environ, "PYTHONPATH": str(root / "service")}
        self.proc = subprocess.Popen([sys.executable, __file__, "--child"], cwd=root, env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def median_s(self, fields: dict) -> float:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps(fields) + "\n")
        self.proc.stdin.flush()
        return statistics.median(json.loads(self.proc.stdout.readline()))

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


def measure(args: argparse.Namespace, filed_root: Path) -> dict:
    load_before = os.getloadavg()[0]
    then, now = Worker(filed_root), Worker(ROOT)
    rows = []
    try:
        for preset in args.presets:
            key = {"preset": preset, "quality": "standard"}
            studio = {**key, "environment": "studio"}
            found: dict[str, list[float]] = {"key then": [], "key now": [], "studio now": []}
            for _ in range(args.rounds):
                found["key then"].append(then.median_s(key))
                found["key now"].append(now.median_s(key))
                found["studio now"].append(now.median_s(studio))
            pairs = list(zip(found["studio now"], found["key then"], found["key now"],
                             strict=True))
            rows.append({"preset": preset,
                         **{f"{label} ms": 1e3 * statistics.median(times)
                            for label, times in found.items()},
                         "studio now / key then": statistics.median(s / t for s, t, _ in pairs),
                         "studio now / key now": statistics.median(s / n for s, _, n in pairs),
                         "key now / key then": statistics.median(n / t for _, t, n in pairs)})
    finally:
        then.close()
        now.close()
    return {"filed": args.filed, "rounds": args.rounds, "per_round": PER_ROUND, "rows": rows,
            "load_average": [load_before, os.getloadavg()[0]]}


def markdown(result: dict) -> str:
    lines = [f"`standard`, 256², the studio; the key light as drawn at `{result['filed']}` (the "
             "last commit before issue 21) and now, alternated in one run, "
             f"{result['rounds']} rounds of {result['per_round']} images; 1-minute load "
             f"average {result['load_average'][0]:.1f} before, "
             f"{result['load_average'][1]:.1f} after. Command: `python bench/speed_env_filed.py`.",
             "", "| preset | key then ms | key now ms | studio now ms | studio now ÷ key then "
             "| studio now ÷ key now | key now ÷ key then |", "|---|---|---|---|---|---|---|"]
    for row in result["rows"]:
        lines.append(f"| {row['preset']} | {row['key then ms']:.2f} | {row['key now ms']:.2f} | "
                     f"{row['studio now ms']:.2f} | {row['studio now / key then']:.2f} | "
                     f"{row['studio now / key now']:.2f} | {row['key now / key then']:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--presets", nargs="+", default=["cd-rom-ashikhmin", "oil-film"])
    parser.add_argument("--filed", default=FILED, help="the commit the issue was filed at")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        serve()
        return
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from report import save  # bench/report.py

    with tempfile.TemporaryDirectory(prefix="opaline-filed-") as folder:
        tree = Path(folder) / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(tree),
                        args.filed], check=True)
        try:
            result = measure(args, tree)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)],
                           check=False)
    save("speed_env_filed", result, markdown(result))


if __name__ == "__main__":
    main()
