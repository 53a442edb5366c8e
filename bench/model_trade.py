"""The trade between the paper's model and the physics it imitates (issue 14).

    python bench/model_trade.py [--size 128] [--presets oil-film ...] [--quick]

For each physical preset: the physical model converged (ground truth: 64 samples,
128 wavelengths, i.e. 3.1 nm bins), the physical model at each quality tier, and
the paper's model at its best on the same scene (same geometry, lights, camera):
its figure parameters (the paired paper preset's material) at the reference tier,
and a least-squares fit of mu_f, alpha, beta, theta1, theta2 and ks to the ground
truth (multi-start, on 48² draft renders of display sRGB), rendered at the
reference tier. Each with time (warm, median of 3, or one draw over 2 s) and error against the ground
truth: CIEDE2000 mean over the object and over where the colour source shows
(ground truth differs from the same scene without specular: streak, bands), and
FLIP over the image.

Writes docs/model_trade.md, docs/model_trade.csv and docs/model_trade.png
(model_trade_report.py), and bench/results/model_trade.json.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import delta_e2000, flip  # noqa: E402
from model_trade_report import plot, to_csv, to_markdown  # noqa: E402
from opaline.output.files import write_atomic  # noqa: E402

# Physical preset → the paper preset whose figure parameters imitate it.
PAIRS = {
    "oil-film": "oil-slick",  # Fig. 14 top
    "soap-bubble": "oil-slick-soft",  # Fig. 14 bottom: the paper's soft thin-film look
    "cd-rom-grating": "cd-rom",  # Fig. 9 left
    "dvd-grating": "cd-rom",
    "nacre-film": "nacre",  # Figs. 10d, 13
}
PAPER_FIELDS = ("mdf", "ex", "ey", "mu_f", "alpha", "beta", "theta1", "theta2", "kd", "ks",
                "albedo", "f0")
FIT_FIELDS = ("mu_f", "alpha", "beta", "theta1", "theta2", "ks")
FIT_BOUNDS = ([0.0, 0.0, 0.0, -np.pi, -np.pi, 0.0], [60.0, 60.0, 60.0, np.pi, np.pi, 20.0])
FIT_SIZE = 48
TIERS = ("draft", "standard", "high", "reference")


class Bench:
    def __init__(self, size: int) -> None:
        from opaline.gl.renderer import Renderer

        self.size = size
        self.renderer = Renderer(None)

    def render(self, preset, size: int | None = None, transparent: bool = False, **fields):
        from opaline.model.params import RenderRequest
        from opaline.model.request import resolve

        size = size or self.size
        request = RenderRequest(preset=preset.name, width=size, height=size, format="png16",
                                transparent=transparent, **fields)
        return self.renderer.render(resolve(request, preset), preset).display

    def timed(self, preset, **fields) -> tuple[np.ndarray, float]:
        self.render(preset, 16, **fields)  # compile and upload outside the timing
        times, image = [], None
        while not times or (len(times) < 3 and times[0] < 2.0):  # slow ones: a single draw
            start = time.perf_counter()
            image = self.render(preset, **fields)
            times.append(time.perf_counter() - start)
        return image, statistics.median(times)


def errors(truth: np.ndarray, test: np.ndarray, mask: np.ndarray, bright: np.ndarray) -> dict:
    de = delta_e2000(truth, test)
    return {"de_object": float(de[mask].mean()), "de_bright": float(de[bright].mean()),
            "flip": flip(truth, test)}


def regions(bench: Bench, preset, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The object's pixels (coverage), and where the colour source shows: pixels whose
    ground truth differs from the same scene without specular (ks = 0) by more than
    0.05 in display units (the streak and highlight, the bands)."""
    cover = bench.render(preset, transparent=True, quality="draft")[..., 3] > 0.5
    plain = bench.render(preset, samples=16, wavelengths=0, ks=0.0)
    shows = np.abs(truth[..., :3] - plain[..., :3]).max(axis=-1) > 0.05
    return cover, cover & shows


def paper_material(paper_preset) -> dict:
    fields = paper_preset.defaults.model_dump(exclude_none=True)
    return {"iridescence": "rotation", **{k: fields[k] for k in PAPER_FIELDS if k in fields}}


def fit(bench: Bench, preset, start: dict, quick: bool) -> tuple[dict, float]:
    """Least squares of the display image against the ground truth at FIT_SIZE."""
    from scipy.optimize import least_squares

    truth = bench.render(preset, FIT_SIZE, samples=16, wavelengths=64)[..., :3].astype(np.float64)
    base = {**start, "mdf": "multipeak"}
    renders = 0

    def residual(x):
        nonlocal renders
        renders += 1
        fields = {**base, **dict(zip(FIT_FIELDS, (float(v) for v in x), strict=True))}
        image = bench.render(preset, FIT_SIZE, quality="draft", **fields)[..., :3]
        return (image - truth).ravel()

    x0 = np.array([start.get(k, 1.0) for k in FIT_FIELDS], dtype=np.float64)
    x0 = np.clip(x0, FIT_BOUNDS[0], FIT_BOUNDS[1])
    starts = [x0] + ([] if quick else [
        np.array([mu, a, b, 0.1, 0.2, x0[5]]) for mu, a, b in ((3.0, 2.0, 1.0), (10.0, 5.0, 1.0),
                                                               (25.0, 1.0, 3.0))])
    best = None
    for x in starts:
        result = least_squares(residual, x, bounds=FIT_BOUNDS, max_nfev=8 if quick else 25,
                               diff_step=0.02, x_scale=[5.0, 5.0, 5.0, 0.3, 0.3, 0.5])
        if best is None or result.cost < best.cost:
            best = result
    fitted = {**base, **dict(zip(FIT_FIELDS, (round(float(v), 4) for v in best.x), strict=True))}
    print(f"    fit after {renders} renders: " + ", ".join(f"{k} {fitted[k]:g}" for k in FIT_FIELDS))
    return fitted, float(best.cost)


def measure(bench: Bench, name: str, quick: bool) -> list[dict]:
    from opaline.model.presets import get_preset

    preset = get_preset(name)
    start = time.perf_counter()
    truth, truth_time = bench.timed(preset, samples=64, wavelengths=128, aa="none")
    print(f"  {name}: ground truth in {truth_time:.2f} s ({time.perf_counter() - start:.0f} s)")
    mask, bright = regions(bench, preset, truth)
    rows = [{"preset": name, "model": "physical", "setting": "ground truth",
             "seconds": truth_time, "de_object": 0.0, "de_bright": 0.0, "flip": 0.0}]
    for tier in TIERS:
        image, seconds = bench.timed(preset, quality=tier)
        rows.append({"preset": name, "model": "physical", "setting": tier, "seconds": seconds,
                     **errors(truth, image, mask, bright)})
    paper = paper_material(get_preset(PAIRS[name]))
    image, seconds = bench.timed(preset, quality="reference", **paper)
    rows.append({"preset": name, "model": "paper", "setting": f"figure ({PAIRS[name]})",
                 "seconds": seconds, **errors(truth, image, mask, bright)})
    fitted, _ = fit(bench, preset, paper, quick)
    image, seconds = bench.timed(preset, quality="reference", **fitted)
    rows.append({"preset": name, "model": "paper", "setting": "least-squares fit",
                 "seconds": seconds, **errors(truth, image, mask, bright),
                 "fit": {k: fitted[k] for k in FIT_FIELDS}})
    write_atomic(ROOT / "docs" / "model_trade" / f"{name}-paper-fit.png", png(image))
    write_atomic(ROOT / "docs" / "model_trade" / f"{name}-truth.png", png(truth))
    for row in rows[-3:]:
        print(f"    {row['setting']:<22} {row['seconds']:7.3f} s  ΔE00 {row['de_object']:5.1f}"
              f" / {row['de_bright']:5.1f}  FLIP {row['flip']:.3f}")
    return rows


def png(image: np.ndarray) -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray((np.clip(image[..., :3], 0, 1) * 255 + 0.5).astype(np.uint8)).save(buf, "PNG")
    return buf.getvalue()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--presets", nargs="*", default=list(PAIRS))
    parser.add_argument("--quick", action="store_true", help="one fit start, few iterations")
    parser.add_argument("--replot", action="store_true",
                        help="rewrite the docs from bench/results/model_trade.json, no renders")
    args = parser.parse_args()
    results = ROOT / "bench" / "results" / "model_trade.json"
    if args.replot:
        saved = json.loads(results.read_text())
        info, rows = saved["info"], saved["rows"]
    else:
        bench = Bench(args.size)
        rows = []
        for name in args.presets:
            rows += measure(bench, name, args.quick)
        gl = bench.renderer.gl.describe()
        info = {"size": args.size, "gl": f"{gl['renderer']} ({gl['backend']})",
                "date": time.strftime("%Y-%m-%d", time.gmtime()),
                "load": f"{os.getloadavg()[1]:.1f} on {os.cpu_count()} cores"}
        write_atomic(results, json.dumps({"info": info, "rows": rows}, indent=2).encode())
    write_atomic(ROOT / "docs" / "model_trade.csv", to_csv(rows))
    write_atomic(ROOT / "docs" / "model_trade.md", to_markdown(rows, info).encode())
    write_atomic(ROOT / "docs" / "model_trade.png", plot(rows, info))
    print("wrote docs/model_trade.{md,csv,png}")


if __name__ == "__main__":
    main()
