"""What a clear coat costs (issue 23): each preset's draft and standard at 256² with the
coat (weight 1, a mirror) over the same material without it, timed in one renderer in
alternating pairs, the best of each side's rounds; prints the ratios and writes
bench/results/coat_cost.{json,md}. Admission prices a coat at workers.admission.COAT_COST.

    python bench/coat_cost.py [--presets sphere oil-film …] [--rounds 4]
"""

from __future__ import annotations

import argparse
import time

from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.pipeline.prepare import prepare
from opaline.workers.admission import COAT_COST
from opaline.workers.factory import RendererFactory
from opaline.workers.tasks import ImageTask
from report import save  # bench/report.py: run from bench/, it is on the path

PRESETS = ("sphere", "oil-film", "cd-rom-grating", "nacre", "anodised-titanium",
           "coated-paint")


def task(preset: str, quality: str, weight: float) -> ImageTask:
    request = RenderRequest(preset=preset, quality=quality, width=256, height=256,
                            coat_weight=weight, coat_roughness=0.0)
    return ImageTask(prepare(request, local_context(None)))


def paired(renderer, tasks: tuple[ImageTask, ImageTask], rounds: int) -> float:
    """Best coated time over best uncoated time, each warmed first, timed in turn."""
    best = [float("inf"), float("inf")]
    for item in tasks:
        item.run(renderer, lambda: False)  # its compile and scene
    for _ in range(rounds):
        for side, item in enumerate(tasks):
            start = time.perf_counter()
            item.run(renderer, lambda: False)
            best[side] = min(best[side], time.perf_counter() - start)
    return best[1] / best[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", nargs="+", default=list(PRESETS))
    parser.add_argument("--rounds", type=int, default=4)
    args = parser.parse_args()
    renderer = RendererFactory()()
    rows = {}
    try:
        for name in args.presets:
            rows[name] = {quality: paired(renderer, (task(name, quality, 0.0),
                                                     task(name, quality, 1.0)), args.rounds)
                          for quality in ("draft", "standard")}
    finally:
        renderer.release()
    ratios = [r for row in rows.values() for r in row.values()]
    lines = ["| preset | coat × none, draft | standard |", "|---|---|---|"]
    lines += [f"| {name} | {row['draft']:.2f} | {row['standard']:.2f} |"
              for name, row in rows.items()]
    lines.append(f"\nrange {min(ratios):.2f}-{max(ratios):.2f}; admission prices "
                 f"{COAT_COST:g}×")
    save("coat_cost", {"rounds": args.rounds, "ratios": rows, "admission": COAT_COST},
         "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
