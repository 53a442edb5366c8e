"""Admission's predicted time against the measured one: presets, the same presets drawing
users' meshes (the Stanford bunny, a torus, the sphere exported as .glb), each under its
own lights and under the sky a mesh gets by default, calibrated in this process as a
worker calibrates.

    python bench/admission.py [--presets sphere,morpho,...] [--size 1024] [--repeat 3]

A ratio under 1 is a job admission would let run past its prediction; a large one is a
job it refuses (too slow) long before it would have missed the deadline. Prints the table
and writes bench/results/admission.{md,json}.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "service"), str(ROOT / "tests")]
from mesh_helpers import mesh_bytes  # noqa: E402
from opaline.local.export import export_material  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from opaline.workers.admission import CostModel  # noqa: E402
from opaline.workers.calibration import CalibrateTask  # noqa: E402
from opaline.workers.tasks import ImageTask  # noqa: E402
from report import save  # noqa: E402

PRESETS = ("sphere", "nacre-film", "soap-bubble", "anodised-titanium", "cd-rom-grating",
           "morpho")


def meshes(folder: Path) -> dict[str, Path | None]:
    (folder / "torus.glb").write_bytes(mesh_bytes("glb"))
    (folder / "sphere.glb").write_bytes(export_material({"preset": "sphere"}, "glb"))
    return {"preset": None, "bunny": ROOT / "tests" / "assets" / "bunny.ply",
            "torus": folder / "torus.glb", "sphere.glb": folder / "sphere.glb"}


def measure(local: LocalRenderer, cost: CostModel, request: RenderRequest,
            repeat: int) -> dict[str, float]:
    """Predicted and measured seconds of the first render (a new variant) and the next."""
    prepared = local.prepare(request)
    task = ImageTask(prepared)
    first_predicted = cost.predict_task(task)
    start = time.perf_counter()
    local.produce(prepared)
    first = time.perf_counter() - start
    cost.warmed(task)
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        local.produce(prepared)
        times.append(time.perf_counter() - start)
    return {"first_s": first, "first_predicted_s": first_predicted,
            "warm_s": statistics.median(times), "warm_predicted_s": cost.predict_task(task)}


def run(presets: list[str], size: int, repeat: int) -> list[dict[str, Any]]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp, LocalRenderer() as local:
        cost = CostModel()
        cost.calibrate(CalibrateTask().run(local.renderer, lambda: False))
        files = meshes(Path(tmp))
        for preset in presets:
            for name, path in files.items():
                # The mesh's default (the sky) and the preset's own lights; the preset's own
                # scene and the same under the sky.
                for environment in ((None, "none") if path else (None, "sky")):
                    request = RenderRequest(preset=preset, width=size, height=size,
                                            quality="standard", environment=environment,
                                            mesh=str(path) if path else None)
                    row = {"preset": preset, "mesh": name, "environment": environment or "default",
                           **measure(local, cost, request, repeat)}
                    rows.append(row)
                    print(f"  {preset} {name} {row['environment']}: first "
                          f"{row['first_predicted_s'] / row['first_s']:.1f}x, warm "
                          f"{row['warm_predicted_s'] / row['warm_s']:.1f}x", flush=True)
    return rows


def table(rows: list[dict[str, Any]], size: int) -> str:
    lines = [f"# Admission: predicted / measured ({size}², standard tier)", "",
             "Command: `python bench/admission.py`. Calibrated in the process, as a worker is; "
             "ratios under 1 would let a job run past its prediction.", "",
             "| preset | mesh | environment | first render (s) | predicted | ratio | "
             "warm (s) | predicted | ratio |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['preset']} | {r['mesh']} | {r['environment']} | {r['first_s']:.3f} | "
                     f"{r['first_predicted_s']:.3f} | {r['first_predicted_s'] / r['first_s']:.1f} "
                     f"| {r['warm_s']:.3f} | {r['warm_predicted_s']:.3f} | "
                     f"{r['warm_predicted_s'] / r['warm_s']:.1f} |")
    ratios = [r[f"{k}_predicted_s"] / r[f"{k}_s"] for r in rows for k in ("first", "warm")]
    lines += ["", f"Predicted / measured over the {len(rows)} jobs: {min(ratios):.2f} to "
                  f"{max(ratios):.1f} (median {statistics.median(ratios):.1f})."]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", default=",".join(PRESETS))
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rows = run(args.presets.split(","), args.size, args.repeat)
    save("admission", {"size": args.size, "rows": rows}, table(rows, args.size))


if __name__ == "__main__":
    main()
