"""The speed/accuracy trade, measured (DESIGN §6): every preset at every tier.

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

Writes docs/accuracy.md, docs/accuracy.csv and docs/accuracy.png atomically.
A hand-written section between the GUIDE markers in docs/accuracy.md is kept.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
# Runnable as a script from a checkout: the bench's metrics and the service package.
sys.path[:0] = [str(ROOT / "bench"), str(ROOT)]
from metrics import all_metrics  # noqa: E402

DOCS = ROOT / "docs"
GUIDE_START, GUIDE_END = "<!-- GUIDE -->", "<!-- /GUIDE -->"
TIER_ORDER = ("draft", "standard", "high", "reference")
METRICS = ("psnr_db", "de2000_mean", "de2000_p95", "flip")
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
    from service.request import TIERS

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
        from service.renderer import Renderer

        self.size = size
        self.renderer = Renderer(None)

    def job(self, preset, setting: Setting, size: int | None = None):
        from service.params import RenderRequest
        from service.request import resolve

        size = size or self.size
        request = RenderRequest(preset=preset.name, width=size, height=size,
                                samples=setting.samples, wavelengths=setting.wavelengths,
                                aa=setting.aa, format="png")
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


# Outputs


def write_atomic(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes it 0600; give it a normal file's mode
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


CSV_COLUMNS = ("preset", "setting", "groups", "samples", "wavelengths", "aa", "ms", "repeats",
               *METRICS, *(f"{m}_rgb" for m in METRICS), "own_ms", "all_features_ms",
               "all_features_ratio", "all_features_max_diff", "conv_base",
               *(f"conv_{m}" for m in METRICS))


def to_csv(rows: list[dict], info: dict) -> bytes:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=[*CSV_COLUMNS, "size", "cpu", "gl", "platform"],
                            lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({**{k: _csv_value(row.get(k)) for k in CSV_COLUMNS},
                         "size": info["size"], "cpu": info["cpu"], "gl": info["gl"],
                         "platform": info["platform"]})
    return out.getvalue().encode()


def _csv_value(value):
    if isinstance(value, float):
        return "inf" if math.isinf(value) else f"{value:.6g}"
    return "" if value is None else value


def fmt(value, digits: int = 2) -> str:
    if value is None:
        return ""
    if isinstance(value, float) and math.isinf(value):
        return "∞"
    return f"{value:.{digits}f}"


def median_of(rows: list[dict], setting: str, key: str, worst=max) -> tuple[float, float]:
    values = [r[key] for r in rows if r["setting"] == setting and key in r]
    finite = [v for v in values if not math.isinf(v)]
    return (statistics.median(values), worst(finite) if finite else values[0])


def summary_table(rows: list[dict]) -> list[str]:
    lines = ["| tier | spp | wl | aa | time/image ms, median (max) | PSNR dB, median (worst) "
             "| ΔE00 mean, median (worst) | ΔE00 p95, median (worst) | FLIP, median (worst) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for tier in TIER_ORDER:
        first = next(r for r in rows if r["setting"] == tier)
        cells = [tier, str(first["samples"]), str(first["wavelengths"]), first["aa"]]
        ms = median_of(rows, tier, "ms")
        cells.append(f"{ms[0]:.0f} ({ms[1]:.0f})")
        for key, worst, digits in (("psnr_db", min, 1), ("de2000_mean", max, 2),
                                   ("de2000_p95", max, 2), ("flip", max, 3)):
            mid, bad = median_of(rows, tier, key, worst)
            cells.append(f"{fmt(mid, digits)} ({fmt(bad, digits)})")
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def full_table(rows: list[dict]) -> list[str]:
    lines = ["| preset | setting | spp | wl | aa | ms | PSNR | ΔE00 mean | ΔE00 p95 | FLIP "
             "| PSNR vs RGB ref | ΔE00 mean vs RGB ref | FLIP vs RGB ref |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['preset']} | {r['setting']} | {r['samples']} | {r['wavelengths']} | {r['aa']} "
            f"| {r['ms']:.1f} | {fmt(r['psnr_db'], 1)} | {fmt(r['de2000_mean'])} "
            f"| {fmt(r['de2000_p95'])} | {fmt(r['flip'], 3)} | {fmt(r.get('psnr_db_rgb'), 1)} "
            f"| {fmt(r.get('de2000_mean_rgb'))} | {fmt(r.get('flip_rgb'), 3)} |")
    return lines


def by_preset(rows: list[dict]) -> dict[str, dict[str, dict]]:
    found: dict[str, dict[str, dict]] = {}
    for r in rows:
        found.setdefault(r["preset"], {})[r["setting"]] = r
    return found


def model_table(rows: list[dict]) -> list[str]:
    lines = ["| preset | RGB ref vs reference: PSNR | ΔE00 mean | ΔE00 p95 | FLIP "
             "| draft FLIP vs RGB ref | standard FLIP vs RGB ref |",
             "|---|---|---|---|---|---|---|"]
    for name, s in by_preset(rows).items():
        rgb = s["RGB ref"]
        lines.append(f"| {name} | {fmt(rgb['psnr_db'], 1)} | {fmt(rgb['de2000_mean'])} "
                     f"| {fmt(rgb['de2000_p95'])} | {fmt(rgb['flip'], 3)} "
                     f"| {fmt(s['draft'].get('flip_rgb'), 3)} "
                     f"| {fmt(s['standard'].get('flip_rgb'), 3)} |")
    return lines


def aa_table(rows: list[dict]) -> list[str]:
    columns = ((1, "none"), (1, "analytic"), (4, "none"), (4, "analytic"), (16, "none"))
    lines = ["| preset | " + " | ".join(f"{n} spp {aa}" for n, aa in columns) + " |",
             "|---" * (len(columns) + 1) + "|"]
    for name, found in by_preset(rows).items():
        cells = []
        for samples, aa in columns:
            row = next((r for r in found.values() if r["samples"] == samples
                        and r["wavelengths"] == 0 and r["aa"] == aa), {})
            cells.append(fmt(row.get("flip_rgb"), 3))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def features_table(rows: list[dict]) -> list[str]:
    lines = ["| preset | setting | own variant ms | all-features ms | ratio "
             "| max abs diff (display) |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        if "all_features_ratio" in r:
            lines.append(f"| {r['preset']} | {r['setting']} | {r['own_ms']:.1f} "
                         f"| {r['all_features_ms']:.1f} | {r['all_features_ratio']:.2f} "
                         f"| {r['all_features_max_diff']:.1e} |")
    return lines


def convergence_table(rows: list[dict]) -> list[str]:
    lines = ["| preset | doubled | error of … | PSNR | ΔE00 mean | ΔE00 p95 | FLIP |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        if "conv_base" in r:
            lines.append(f"| {r['preset']} | {r['setting']} | {r['conv_base']} "
                         f"| {fmt(r['conv_psnr_db'], 1)} | {fmt(r['conv_de2000_mean'])} "
                         f"| {fmt(r['conv_de2000_p95'])} | {fmt(r['conv_flip'], 3)} |")
    return lines


def kept_guide(path: Path) -> str:
    if path.exists():
        text = path.read_text()
        if GUIDE_START in text and GUIDE_END in text:
            return text[text.index(GUIDE_START):text.index(GUIDE_END) + len(GUIDE_END)]
    return (f"{GUIDE_START}\n_(Write the \"which tier to pick when\" guidance here; the "
            f"benchmark keeps this section.)_\n{GUIDE_END}")


def to_markdown(rows: list[dict], info: dict, guide: str) -> str:
    quick = not any("samples" in r["groups"] for r in rows)
    parts = [
        "# Accuracy against speed",
        "",
        guide,
        "",
        f"Measured by `{info['command']}` on {info['date']} in {info['wall_s']:.0f} s. "
        f"Machine: {info['cpu']}; {info['platform']}; GL: {info['gl']}; Python {info['python']}.",
        "",
        f"Images are {info['size']}² display (sRGB) images; errors are over the whole frame "
        "against the same preset's `reference` tier. Time is the median of at least 3 warm "
        "draws + readbacks of the display image (5 when one takes under 0.25 s); the reference "
        "and the convergence checks are timed once. Load average (1 min) at start / end: "
        f"{info['load'][0]:.1f} / {info['load'][1]:.1f} on {os.cpu_count()} cores (the machine "
        "is shared: higher load inflates times, not errors). FLIP is LDR-FLIP (flip-evaluator, 67 ppd); "
        "ΔE00 is CIEDE2000 (colour-science, sRGB → XYZ → Lab, D65).",
        "",
        "## Tiers, over all presets",
        "",
        *summary_table(rows),
        "",
        "## The paper's RGB model against the continuous spectrum",
        "",
        "`RGB ref` is the RGB model converged in the image plane (64 spp, wavelengths 0, aa "
        "none). Its error against the spectral reference is the model's own error, which no "
        "number of samples removes; the draft and standard tiers' FLIP against `RGB ref` is "
        "their sampling error alone.",
        "",
        *model_table(rows),
        "",
    ]
    if not quick:
        parts += [
            "## Anti-aliasing: FLIP against the RGB reference (wavelengths 0)",
            "",
            *aa_table(rows),
            "",
            "## Is the reference converged?",
            "",
            "The reference (64 spp, 32 wl) against each knob doubled on its own: the RGB model's "
            "64-spp image (`RGB ref`) against 128 spp (sampling), and the 32-wavelength image "
            "at 16 spp against 64 wavelengths (spectrum). Small errors here mean the reference "
            "is converged well below the errors of the tiers.",
            "",
            *convergence_table(rows),
            "",
        ]
    parts += [
        "## The all-features program against the scene's own variant",
        "",
        "Same job drawn by the variant compiled with only the scene's features and by the one "
        "with every optional feature compiled in at neutral values "
        "(`render(job, all_features=True)`), timed in alternating pairs; ratio = median over "
        "pairs of all-features / own. A max abs diff above 1e-5 means the all-features "
        "program does not draw the same image (`1 spp` is wavelengths 0, aa none).",
        "",
        *features_table(rows),
        "",
        "## Every setting",
        "",
        *full_table(rows),
        "",
        "![time against error](accuracy.png)",
        "",
    ]
    return "\n".join(parts)


# The plot

SWEEPS = (  # group, marker, colour, label
    ("samples", "o", "tab:blue", "samples 1→128 (wl 0, aa none)"),
    ("wavelengths", "s", "tab:green", "wavelengths 3→64 (16 spp, aa none)"),
    ("aa", "^", "tab:orange", "analytic AA, 1 and 4 spp (wl 0)"),
)


def setting_stats(rows: list[dict], key: str) -> list[dict]:
    """Per setting, over presets: median time, median / min / max error."""
    out = []
    for name in dict.fromkeys(r["setting"] for r in rows):
        found = [r for r in rows if r["setting"] == name]
        values = [r[key] for r in found]
        out.append({"setting": name, "groups": found[0]["groups"], "samples": found[0]["samples"],
                    "wavelengths": found[0]["wavelengths"], "aa": found[0]["aa"],
                    "ms": statistics.median(r["ms"] for r in found),
                    "mid": statistics.median(values), "lo": min(values), "hi": max(values)})
    return out


def sweep_panel(ax, rows: list[dict], key: str, label: str) -> None:
    stats = setting_stats(rows, key)
    for group, marker, colour, text in SWEEPS:
        points = [s for s in stats if group in s["groups"].split("+")
                  and (group != "aa" or s["aa"] == "analytic")]
        points.sort(key=lambda s: (s["samples"], s["wavelengths"]))
        if not points:
            continue
        xs = [p["ms"] for p in points]
        ax.vlines(xs, [p["lo"] for p in points], [p["hi"] for p in points], colour, alpha=0.3,
                  lw=4)
        ax.plot(xs, [p["mid"] for p in points], marker=marker, color=colour, ms=7, label=text,
                ls="-")
        if group in ("samples", "wavelengths"):
            for p in points:
                tag = f"{p['samples']}" if group == "samples" else f"{p['wavelengths']}"
                ax.annotate(tag, (p["ms"], p["mid"]), textcoords="offset points", xytext=(0, -13),
                            ha="center", fontsize=8, color=colour)
    rgb = [s for s in setting_stats([r for r in rows if f"{key}_rgb" in r], f"{key}_rgb")
           if "samples" in s["groups"].split("+") and s["mid"] > 0]
    rgb.sort(key=lambda s: s["samples"])
    ax.plot([s["ms"] for s in rgb], [s["mid"] for s in rgb], marker="o", mfc="white",
            color="tab:blue", ls="--", label="samples, error vs RGB ref (sampling error alone)")
    for s in stats:
        if s["setting"] in TIER_ORDER[:-1]:
            ax.plot(s["ms"], s["mid"], marker="*", color="black", ms=16, ls="none", zorder=5)
            ax.annotate(s["setting"], (s["ms"], s["mid"]), textcoords="offset points",
                        xytext=(8, 6), fontsize=11, weight="bold")
    ref = next(s for s in stats if s["setting"] == "reference")
    ax.axvline(ref["ms"], color="black", ls=":", lw=1)
    ax.annotate("reference\n(error 0)", (ref["ms"], 0.97), xycoords=("data", "axes fraction"),
                ha="right", va="top", fontsize=10, xytext=(-4, 0), textcoords="offset points")
    ax.set(xscale="log", yscale="log", xlabel="time per image, ms (median over presets; log)",
           ylabel=f"{label} (median over presets; bar: range; log)")
    ax.grid(True, which="both", alpha=0.25)


def preset_panel(ax, rows: list[dict]) -> None:
    markers = {"draft": "o", "standard": "s", "high": "^"}
    for i, (name, found) in enumerate(by_preset(rows).items()):
        colour = f"C{i % 10}"
        tiers = [found[t] for t in markers if t in found]
        ax.plot([t["ms"] for t in tiers], [t["flip"] for t in tiers], color=colour, lw=1.2,
                label=name)
        for t in tiers:
            ax.plot(t["ms"], t["flip"], marker=markers[t["setting"]], color=colour, ms=8)
    for tier, marker in markers.items():
        ax.plot([], [], marker=marker, color="black", ls="none", label=tier)
    ax.set(xscale="log", yscale="log", xlabel="time per image, ms (log)",
           ylabel="FLIP vs reference (log)", title="Per preset: draft → standard → high")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(True, which="both", alpha=0.25)


def plot(rows: list[dict], info: dict) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(20, 6.5), constrained_layout=True)
    sweep_panel(axes[0], rows, "flip", "FLIP vs reference")
    axes[0].set_title("FLIP: every setting, median over presets")
    axes[0].legend(fontsize=8, loc="lower left")
    sweep_panel(axes[1], rows, "de2000_mean", "CIEDE2000 mean vs reference")
    axes[1].set_title("CIEDE2000 mean: every setting, median over presets")
    preset_panel(axes[2], rows)
    fig.suptitle(f"Opaline speed against accuracy, {info['size']}², {len(by_preset(rows))} "
                 f"presets — {info['cpu']}; {info['gl']}", fontsize=11)
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=110)
    plt.close(fig)
    return out.getvalue()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--presets", nargs="+", help="default: every preset")
    parser.add_argument("--quick", action="store_true",
                        help="tiers and the RGB reference only, one timed render each")
    parser.add_argument("--out", type=Path, default=DOCS, help="where accuracy.* go")
    parser.add_argument("--images", type=Path, help="also write a strip of the tiers per preset")
    args = parser.parse_args()

    from service.presets import all_presets

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
