"""The accuracy benchmark's tables: docs/accuracy.md and docs/accuracy.csv from its rows.

A row is one setting of one preset, as ``accuracy.measure_preset`` makes it:
the setting, its time, its errors against the preset's reference (and, for
wavelengths 0, against the RGB reference), and where measured the
convergence check and the all-features cost.
"""

from __future__ import annotations

import csv
import io
import math
import os
import statistics
from pathlib import Path

GUIDE_START, GUIDE_END = "<!-- GUIDE -->", "<!-- /GUIDE -->"
TIER_ORDER = ("draft", "standard", "high", "reference")
METRICS = ("psnr_db", "de2000_mean", "de2000_p95", "flip")

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
