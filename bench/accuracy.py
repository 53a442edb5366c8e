"""The speed/accuracy trade, measured (docs/design.md §8): every preset at every tier.

    python bench/accuracy.py [--size 256] [--presets cd-rom ...] [--quick] [--images DIR]

For each preset, renders the quality tiers and explicit settings (a samples
sweep in the paper's RGB model, a wavelengths sweep, analytic anti-aliasing
against none), times each (warm, median of at least 3 draws + readbacks of the
display image) and measures its error against the preset's ``reference`` tier:
PSNR, CIEDE2000 mean and 95th percentile, FLIP (bench/metrics.py). Also: the
RGB model's converged image (64 samples, wavelengths 0, aa none) as a second
reference, to separate sampling error from model error; the all-features
program against the scene's own variant; and (not with --quick) how far the
reference is from converged, each knob doubled on its own (128 against 64
samples in the RGB model, 64 against 32 wavelengths at 16 samples).

Writes docs/accuracy.md, docs/accuracy.csv (accuracy_report.py) and
docs/accuracy.png (accuracy_plot.py) atomically. A hand-written section
between the GUIDE markers in docs/accuracy.md is kept.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
# Runnable as a script from a checkout: the bench's metrics and the service package.
sys.path[:0] = [str(ROOT / "bench"), str(ROOT)]
from accuracy_plot import plot  # noqa: E402
from accuracy_report import TIER_ORDER, kept_guide, to_csv, to_markdown  # noqa: E402
from metrics import all_metrics  # noqa: E402
from opaline.output.files import write_atomic  # noqa: E402

DOCS = ROOT / "docs"
# The all-features program is timed on these; "1 spp" (aa none) checks that it keeps the job's AA.
ALL_FEATURE_SETTINGS = ("draft", "standard", "high", "1 spp")


@dataclass
class Setting:
    """One point on the curve: samples, wavelengths and anti-aliasing, and why it is here."""

    name: str
    samples: int
    wavelengths: int
    aa: str
    groups: list[str] = field(default_factory=list)

    @property
    def key(self) -> tuple[int, int, str]:
        return self.samples, self.wavelengths, self.aa


def settings(quick: bool) -> list[Setting]:
    """The tiers, then the explicit sweeps; a setting listed twice is rendered once."""
    from opaline.model.request import TIERS

    wanted = [Setting(t, int(TIERS[t]["samples"]), int(TIERS[t]["wavelengths"]),
                      str(TIERS[t]["aa"]), ["tier"]) for t in TIER_ORDER]
    wanted.append(Setting("RGB ref", 64, 0, "none", ["rgb-ref"]))
    if not quick:
        wanted += [Setting(f"{n} spp", n, 0, "none", ["samples"]) for n in (1, 4, 16, 64)]
        wanted += [Setting(f"{n} wl", 16, n, "none", ["wavelengths"]) for n in (3, 8, 16, 32)]
        wanted += [Setting(f"{n} spp {aa}", n, 0, aa, ["aa"])
                   for n in (1, 4) for aa in ("none", "analytic")]
    merged: dict[tuple, Setting] = {}
    for item in wanted:
        if item.key in merged:
            merged[item.key].groups += [g for g in item.groups if g not in merged[item.key].groups]
        else:
            merged[item.key] = item
    return list(merged.values())


def convergence_settings() -> list[tuple[Setting, str]]:
    """How far the reference is from converged, each knob doubled on its own, as (setting, the
    setting it doubles): the RGB model at 128 against 64 samples, and 64 against 32
    wavelengths at 16 samples. A quarter of the cost of doubling the reference itself."""
    return [(Setting("128 spp", 128, 0, "none", ["samples", "convergence"]), "RGB ref"),
            (Setting("64 wl", 16, 64, "none", ["wavelengths", "convergence"]), "32 wl")]


# Rendering and timing


class Bench:
    """One renderer, one size; renders settings of a preset, warm and timed."""

    def __init__(self, size: int) -> None:
        from opaline.gl.renderer import Renderer

        self.size = size
        self.renderer = Renderer(None)

    def job(self, preset, setting: Setting, size: int | None = None):
        from opaline.model.params import RenderRequest
        from opaline.model.request import resolve

        size = size or self.size
        request = RenderRequest(preset=preset.name, width=size, height=size,
                                samples=setting.samples, wavelengths=setting.wavelengths,
                                aa=setting.aa, format="png16")  # float display values
        return resolve(request, preset)

    def timed(self, preset, setting: Setting, repeats: int | None,
              all_features: bool = False) -> tuple[np.ndarray, list[float]]:
        """The display image and the seconds of each warm render. ``repeats=None``: 3, or 5
        when one render takes under a quarter second."""
        # Warm-up at 16²: compiles the variant and uploads the scene without a full draw.
        self.renderer.render(self.job(preset, setting, 16), preset, all_features=all_features)
        job = self.job(preset, setting)
        times: list[float] = []
        image = None
        while not times or len(times) < (repeats or (5 if times[0] < 0.25 else 3)):
            start = time.perf_counter()
            image = self.renderer.render(job, preset, all_features=all_features).display
            times.append(time.perf_counter() - start)
        return image, times

    def release(self) -> None:
        self.renderer.release()


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


def measure_preset(bench: Bench, preset, quick: bool, images: Path | None) -> list[dict]:
    """Every setting of one preset: time, errors vs the two references, all-features cost."""
    rows, shown = [], {}
    todo = settings(quick)
    reference = next(s for s in todo if s.name == "reference")
    checks = [] if quick else convergence_settings()
    rendered = {}
    for setting in todo + [check for check, _ in checks]:
        # The reference and the convergence checks are the slow ones: one timed render each.
        slow = setting is reference or "convergence" in setting.groups
        image, times = bench.timed(preset, setting, 1 if slow or quick else None)
        rendered[setting.name] = image
        rows.append({"preset": preset.name, "setting": setting.name,
                     "groups": "+".join(setting.groups), "samples": setting.samples,
                     "wavelengths": setting.wavelengths, "aa": setting.aa,
                     "ms": 1e3 * statistics.median(times), "repeats": len(times)})
        if setting.name in TIER_ORDER or setting.name == "RGB ref":
            shown[setting.name] = image
    ref_image, rgb_image = rendered["reference"], rendered["RGB ref"]
    for row in rows:
        image = rendered[row["setting"]]
        row.update(all_metrics(ref_image, image))
        if row["wavelengths"] == 0:
            row.update({f"{k}_rgb": v for k, v in all_metrics(rgb_image, image).items()})
    for check, base in checks:
        row = next(r for r in rows if r["setting"] == check.name)
        row["conv_base"] = base
        row.update({f"conv_{k}": v
                    for k, v in all_metrics(rendered[check.name], rendered[base]).items()})
    for row in rows:
        if row["setting"] in ALL_FEATURE_SETTINGS:
            row.update(all_features_cost(bench, preset, row, rendered[row["setting"]]))
    if images is not None:
        save_strip(images / f"{preset.name}.png", [shown[k] for k in (*TIER_ORDER, "RGB ref")])
    return rows


def all_features_cost(bench: Bench, preset, row: dict, own: np.ndarray) -> dict:
    """Own variant and all-features program, timed in alternating pairs (the ratio is the
    median of the pairs' ratios, which cancels slow drift in load); is the image the same?"""
    setting = Setting(row["setting"], row["samples"], row["wavelengths"], row["aa"])
    own_times, all_times = [], []
    image = own
    for _ in range(3 if row["ms"] > 250 else 5):
        image, t_all = bench.timed(preset, setting, 1, all_features=True)
        _, t_own = bench.timed(preset, setting, 1)
        all_times += t_all
        own_times += t_own
    ratio = statistics.median(a / o for a, o in zip(all_times, own_times, strict=True))
    return {"own_ms": 1e3 * statistics.median(own_times),
            "all_features_ms": 1e3 * statistics.median(all_times), "all_features_ratio": ratio,
            "all_features_max_diff": float(np.abs(image - own).max())}


def save_strip(path: Path, images: list[np.ndarray]) -> None:
    from PIL import Image

    strip = np.concatenate([np.clip(im[..., :3], 0, 1) for im in images], axis=1)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray((strip * 255 + 0.5).astype(np.uint8)).save(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--presets", nargs="+", help="default: every preset")
    parser.add_argument("--quick", action="store_true",
                        help="tiers and the RGB reference only, one timed render each")
    parser.add_argument("--out", type=Path, default=DOCS, help="where accuracy.* go")
    parser.add_argument("--images", type=Path, help="also write a strip of the tiers per preset")
    args = parser.parse_args()

    from opaline.model.presets import all_presets

    presets = all_presets()
    names = args.presets or list(presets)
    unknown = [n for n in names if n not in presets]
    if unknown:
        parser.error(f"unknown presets {unknown}; known: {', '.join(presets)}")
    started = time.perf_counter()
    bench = Bench(args.size)
    info = {**machine(bench), "size": args.size, "load": [os.getloadavg()[0]],
            "command": " ".join(["python bench/accuracy.py", *sys.argv[1:]]),
            "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")}
    rows = []
    try:
        for name in names:
            t0 = time.perf_counter()
            rows += measure_preset(bench, presets[name], args.quick, args.images)
            print(f"{name}: {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
    finally:
        bench.release()
    info["wall_s"] = time.perf_counter() - started
    info["load"].append(os.getloadavg()[0])
    markdown = to_markdown(rows, info, kept_guide(args.out / "accuracy.md"))
    write_atomic(args.out / "accuracy.csv", to_csv(rows, info))
    write_atomic(args.out / "accuracy.png", plot(rows, info))
    write_atomic(args.out / "accuracy.md", markdown.encode())
    print(markdown)


if __name__ == "__main__":
    main()
