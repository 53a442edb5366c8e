"""Environment lighting's quality knob, measured: K directional lights (median cut) against
time and error, per environment, against the K=256 render as the converged reference.

    python bench/environment_lights.py [--size 256] [--presets sphere cd-rom]

Each point renders the preset under the environment at the standard tier's samples (4,
RGB model), times it warm (median of 3 renders with readback) and compares the display
image with K=256 (PSNR, CIEDE2000 mean/p95, FLIP: bench/metrics.py). Prints the table
and writes bench/results/environment_lights.{md,json}.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import all_metrics  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from report import save  # noqa: E402

COUNTS = (1, 2, 4, 8, 16, 32, 64, 128)
REFERENCE = 256


def display(local: LocalRenderer, preset: str, env: str, count: int, size: int
            ) -> tuple[np.ndarray, float]:
    request = RenderRequest(preset=preset, environment=env, environment_lights=count,
                            width=size, height=size, quality="standard", format="png16")
    job = local.job(request)
    local.renderer.render(job)  # compile this K's variant
    times = []
    for _ in range(3):
        start = time.perf_counter()
        frame = local.renderer.render(job)
        times.append(time.perf_counter() - start)
    assert frame.display is not None
    return frame.display[..., :3], statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--presets", nargs="+", default=["sphere", "cd-rom"])
    args = parser.parse_args()
    rows = []
    with LocalRenderer() as local:
        for preset in args.presets:
            for env in ("studio", "sky"):
                reference, ref_s = display(local, preset, env, REFERENCE, args.size)
                for count in COUNTS:
                    image, seconds = display(local, preset, env, count, args.size)
                    rows.append({"preset": preset, "environment": env, "K": count,
                                 "ms": seconds * 1e3, "ref_ms": ref_s * 1e3,
                                 **all_metrics(reference, image)})
                    print(json.dumps(rows[-1]))
    lines = [f"# Environment lights (median cut): K against time and error, {args.size}²",
             "", "Reference: K=256 at the same samples (standard tier: 4, RGB model). "
             "Command: `python bench/environment_lights.py`.", "",
             "| preset | environment | K | ms | ms (K=256) | PSNR dB | ΔE00 mean | ΔE00 p95 | FLIP |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['preset']} | {r['environment']} | {r['K']} | {r['ms']:.1f} | "
                     f"{r['ref_ms']:.1f} | {r['psnr_db']:.1f} | {r['de2000_mean']:.2f} | "
                     f"{r['de2000_p95']:.2f} | {r['flip']:.4f} |")
    save("environment_lights", rows, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
