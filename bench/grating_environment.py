"""A grating's orders under an environment, measured: each tier's pieces of the orders'
curve against the same reads converged, on the grating presets' own discs.

    python bench/grating_environment.py [--size 128] [--environments studio sky]

The grating presets' lobes (A-S 3000 × 30000) are far narrower than the brute-force
reference's disc samples can find (bench/environment_accuracy.py measures its `grating`
case, a lobe of 100, that way instead). Here the reference is the reference tier with
``--reference-reads`` reads a pixel, read at the mip level of each lobe: what the tiers
converge to as their pieces shrink; ``converged`` is its FLIP against half as many. Each
tier renders as a user gets it, and at twice its pieces beside it. Prints the table,
writes bench/results/grating_environment.{md,json}.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import all_metrics  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from opaline.model.tiers import TIERS  # noqa: E402
from report import save  # noqa: E402

PRESETS = ("cd-rom-grating", "dvd-grating")
TIER_NAMES = ("draft", "standard", "high")


def render(local: LocalRenderer, fields: dict[str, Any]) -> tuple[np.ndarray, float]:
    job = local.job(RenderRequest(**fields, format="png16"))
    local.renderer.render(job)  # compiled and warm
    start = time.perf_counter()
    frame = local.renderer.render(job)
    assert frame.display is not None
    return frame.display[..., :3], time.perf_counter() - start


def measure(local: LocalRenderer, preset: str, environment: str, size: int, reads: int
            ) -> list[dict[str, Any]]:
    base = dict(preset=preset, width=size, height=size, environment=environment)
    reference, _ = render(local, {**base, "quality": "reference", "environment_samples": reads})
    half, _ = render(local, {**base, "quality": "reference",
                             "environment_samples": reads // 2})
    converged = all_metrics(reference, half)["flip"]
    rows = []
    for tier in TIER_NAMES:
        own = TIERS[tier].environment_samples_grating
        for pieces in (own, 2 * own):
            image, seconds = render(local, {**base, "quality": tier,
                                            "environment_samples": pieces})
            rows.append({"preset": preset, "environment": environment, "tier": tier,
                         "pieces": pieces, "tier_default": pieces == own,
                         "ms": seconds * 1e3, "converged_flip": converged,
                         **all_metrics(reference, image)})
            print(rows[-1], flush=True)
    return rows


def table(rows: list[dict[str, Any]], size: int, reads: int) -> str:
    lines = [f"# A grating's orders under an environment, {size}²", "",
             f"Reference: the reference tier at {reads} reads a pixel; `converged` is its "
             "FLIP against half as many. Command: `python bench/grating_environment.py`.", "",
             "| preset | environment | tier | pieces | ms | FLIP | ΔE00 mean | ΔE00 p95 | "
             "converged |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        mark = " (tier)" if r["tier_default"] else ""
        lines.append(f"| {r['preset']} | {r['environment']} | {r['tier']} | {r['pieces']}{mark} "
                     f"| {r['ms']:.0f} | {r['flip']:.4f} | {r['de2000_mean']:.2f} | "
                     f"{r['de2000_p95']:.2f} | {r['converged_flip']:.4f} |")
    worst = {t: max(r["flip"] for r in rows if r["tier"] == t and r["tier_default"])
             for t in TIER_NAMES}
    lines += ["", "Worst FLIP at each tier's own pieces: "
              + ", ".join(f"{t} {v:.3f}" for t, v in worst.items())]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--environments", nargs="+", default=["studio", "sky"])
    parser.add_argument("--presets", nargs="+", default=list(PRESETS))
    parser.add_argument("--reference-reads", type=int, default=4096)
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    with LocalRenderer() as local:
        for preset in args.presets:
            for environment in args.environments:
                rows += measure(local, preset, environment, args.size, args.reference_reads)
    save("grating_environment", rows, table(rows, args.size, args.reference_reads))


if __name__ == "__main__":
    main()
