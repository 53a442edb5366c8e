"""The accuracy benchmark's tables: docs/accuracy.md and docs/accuracy.csv from its rows.

A row is one point (samples, wavelengths, aa) of one preset and material variant,
as ``accuracy_grid.measure`` makes it: its time and its errors against the
converged spectrum (and, for wavelengths 0, against the RGB model converged).
``facts`` hold each preset and variant's reference checks and model error.
"""

from __future__ import annotations

import math
from pathlib import Path

from accuracy_front import TIER_ORDER, base_rows, front, placement, point_of, tier_point
from accuracy_grid import REFERENCE, RGB_REFERENCE, SAMPLES, WAVELENGTHS

GUIDE_START, GUIDE_END = "<!-- GUIDE -->", "<!-- /GUIDE -->"
def fmt(value, digits: int = 3) -> str:
    if value is None:
        return ""
    if isinstance(value, float) and math.isinf(value):
        return "∞"
    return f"{value:.{digits}f}"


def name(row: dict) -> str:
    return f"{row['samples']} spp × {row['wavelengths']} wl{', analytic' if row['aa'] == 'analytic' else ''}"


def tier_table(rows: list[dict], paired: dict) -> list[str]:
    lines = ["| preset | tier | setting | ms (model) | × draft (model) | × draft (paired) | FLIP "
             "| ΔE00 p95 | best FLIP in the same time | on the front |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for p in placement(rows):
        row = tier_point(base_rows(rows, p["preset"]), p["tier"])
        ratio = 1.0 if p["tier"] == "draft" else paired.get(p["preset"], {}).get(p["tier"])
        lines.append(f"| {p['preset']} | {p['tier']} | {name(row)} | {p['ms']:.1f} "
                     f"| {p['ratio']:.2f} | {fmt(ratio, 2)} | {fmt(p['flip'])} "
                     f"| {fmt(p['de2000_p95'], 2)} | {fmt(p['front_flip'])} "
                     f"| {'yes' if p['on_front'] else 'no'} |")
    return lines


def time_model_table(info: dict) -> list[str]:
    lines = ["| preset | a (ms) | b (ms per sample) | c (ms per sample·wavelength) "
             "| d (extra for analytic AA) | old draft (1 spp RGB analytic) × draft, paired |",
             "|---|---|---|---|---|---|"]
    for preset, (a, b, c, d) in info.get("time_model", {}).items():
        old = info.get("tier_ratios", {}).get(preset, {}).get("old draft")
        lines.append(f"| {preset} | {a:.2f} | {b:.2f} | {c:.3f} | {d:.3f} | {fmt(old, 2)} |")
    return lines


def model_table(rows: list[dict], facts: list[dict]) -> list[str]:
    lines = ["| preset | model error: FLIP | ΔE00 p95 | sampling error (FLIP vs RGB converged): "
             "1 spp | 4 spp | 16 spp | total FLIP, RGB 16 spp | total FLIP, 1 spp × 8 wl |",
             "|---|---|---|---|---|---|---|---|"]
    for f in facts:
        if f["variant"] != "base":
            continue
        found = {point_of(r): r for r in base_rows(rows, f["preset"])}
        rgb = [found.get((n, 0, "none"), {}).get("flip_sampling") for n in (1, 4, 16)]
        lines.append(f"| {f['preset']} | {fmt(f['model_flip'])} | {fmt(f['model_de2000_p95'], 2)} "
                     f"| {' | '.join(fmt(v) for v in rgb)} "
                     f"| {fmt(found.get((16, 0, 'none'), {}).get('flip'))} "
                     f"| {fmt(found.get((1, 8, 'none'), {}).get('flip'))} |")
    return lines


def aa_table(rows: list[dict]) -> list[str]:
    columns = ((1, "none"), (1, "analytic"), (4, "none"), (4, "analytic"), (16, "none"))
    lines = ["| preset | " + " | ".join(f"{n} spp {aa}" for n, aa in columns)
             + " | 1 spp analytic beats 4 spp none |", "|---" * (len(columns) + 2) + "|"]
    for preset in dict.fromkeys(r["preset"] for r in rows):
        found = {point_of(r): r for r in base_rows(rows, preset)}
        if (1, 0, "analytic") not in found:
            continue
        values = [found[(n, 0, aa)]["flip_sampling"] for n, aa in columns]
        lines.append(f"| {preset} | " + " | ".join(fmt(v, 4) for v in values)
                     + f" | {'yes' if values[1] < values[2] else 'no'} |")
    return lines


def wavelength_table(rows: list[dict], samples: int) -> list[str]:
    lines = ["| preset | " + " | ".join(f"{w} wl" for w in WAVELENGTHS) + " |",
             "|---" * (len(WAVELENGTHS) + 1) + "|"]
    for preset in dict.fromkeys(r["preset"] for r in rows):
        found = {point_of(r): r for r in base_rows(rows, preset)}
        lines.append(f"| {preset} | " + " | ".join(
            fmt(found[(samples, w, "none")]["flip"]) for w in WAVELENGTHS) + " |")
    return lines


def convergence_table(facts: list[dict]) -> list[str]:
    lines = ["| preset | material | FLIP, reference vs half | ΔE00 p95, reference vs half "
             "| RGB model: FLIP, converged vs half | floor (10× the larger FLIP) |",
             "|---|---|---|---|---|---|"]
    for f in facts:
        worst = max(f["conv_flip"], f.get("rgb_conv_flip", 0.0))
        lines.append(f"| {f['preset']} | {f['variant']} | {fmt(f['conv_flip'], 4)} "
                     f"| {fmt(f['conv_de2000_p95'], 3)} | {fmt(f.get('rgb_conv_flip'), 4)} "
                     f"| {fmt(10 * worst)} |")
    return lines


def front_tables(rows: list[dict]) -> list[str]:
    """Per preset, the union of its two fronts, fastest first, marked by which front."""
    out = []
    for preset in dict.fromkeys(r["preset"] for r in rows):
        found = base_rows(rows, preset)
        on_flip = {point_of(r) for r in front(found, "flip")}
        on_de = {point_of(r) for r in front(found, "de2000_p95")}
        out += [f"**{preset}**", "", "| setting | ms (model) | ms (measured) | FLIP | ΔE00 p95 "
                "| front |", "|---|---|---|---|---|---|"]
        for r in sorted(found, key=lambda r: r["ms"]):
            marks = [label for label, points in (("FLIP", on_flip), ("ΔE00", on_de))
                     if point_of(r) in points]
            if marks:
                out.append(f"| {name(r)} | {r['ms']:.1f} | {r.get('ms_measured', r['ms']):.1f} "
                           f"| {fmt(r['flip'])} | {fmt(r['de2000_p95'], 2)} "
                           f"| {', '.join(marks)} |")
        out.append("")
    return out


def variant_table(rows: list[dict]) -> list[str]:
    variants = list(dict.fromkeys(r["variant"] for r in rows))
    lines = ["| preset | tier | " + " | ".join(f"FLIP, {v}" for v in variants) + " |",
             "|---" * (len(variants) + 2) + "|"]
    for preset in dict.fromkeys(r["preset"] for r in rows):
        for tier in TIER_ORDER:
            cells = []
            for v in variants:
                row = tier_point([r for r in rows if r["preset"] == preset
                                  and r["variant"] == v], tier)
                cells.append(fmt(row["flip"]) if row else "")
            lines.append(f"| {preset} | {tier} | " + " | ".join(cells) + " |")
    return lines


def kept_guide(path: Path) -> str:
    if path.exists():
        text = path.read_text()
        if GUIDE_START in text and GUIDE_END in text:
            return text[text.index(GUIDE_START):text.index(GUIDE_END) + len(GUIDE_END)]
    return (f"{GUIDE_START}\n_(Write the \"which tier to pick when\" guidance here; the "
            f"benchmark keeps this section.)_\n{GUIDE_END}")


def to_markdown(rows: list[dict], facts: list[dict], info: dict, guide: str) -> str:
    s, w = REFERENCE
    rs, _ = RGB_REFERENCE
    return "\n".join([
        "# Accuracy against speed",
        "",
        guide,
        "",
        f"Measured by `{info['command']}` on {info['date']} in {info['wall_s']:.0f} s. "
        f"Machine: {info['cpu']}; {info['platform']}; GL: {info['gl']}; Python {info['python']}. "
        f"Load average (1 min) at start / end: {info['load'][0]:.1f} / {info['load'][1]:.1f} "
        "(the machine is shared: load inflates times, not errors)."
        + "".join(f" Then `{m['command']}` on {m['date']} in {m['wall_s']:.0f} s measured those "
                  "presets again, the others' rows kept." for m in info.get("merged", []))
        + "".join(f" Then `{m['command']}` on {m['date']} in {m['wall_s']:.0f} s timed the "
                  "tiers against draft again." for m in info.get("retimed", [])),
        "",
        f"Images are {info['size']}² display (sRGB) images of each preset's own material. Grid: "
        f"samples {', '.join(map(str, SAMPLES))} × wavelengths "
        f"{', '.join(map(str, WAVELENGTHS))} (0 = the paper's RGB model) × anti-aliasing none / "
        "analytic (multi-peak presets only). Time: the fastest of 3 warm renders including the "
        "display readback. Errors over the whole frame against the converged spectrum "
        f"({s} spp × {w} wavelengths, wavelengths shifted per sample, so {s * w} points of the "
        f"spectrum per pixel; aa none); the RGB model's sampling error against the RGB model "
        f"converged ({rs} spp). FLIP is LDR-FLIP (flip-evaluator, 67 ppd); ΔE00 is CIEDE2000 "
        "(colour-science, sRGB → XYZ → Lab, D65). Every point is in docs/accuracy.csv.",
        "",
        "## Where the tiers sit",
        "",
        "Each tier's time over draft's on the same preset, its errors, and the best FLIP any "
        "measured point reaches in at most the same time (the front under it). Times: "
        "`model` is the fitted cost model below (what the fronts, the tiers and the "
        "quality=auto table use); `paired` is the tier and draft rendered in 7 alternating "
        "pairs, median of the pairs' ratios.",
        "",
        *tier_table(rows, info.get("tier_ratios", {})),
        "",
        "### Time model",
        "",
        "On a shared 2-core machine the fastest of 3 renders of one point still scatters by "
        "10-50 %, enough to reorder neighbouring points. Per preset, ms = a + b·samples + "
        "(c + d·[analytic])·samples·max(wavelengths, 3) is fitted (non-negative least squares "
        "on relative error) to all the preset's measured points; docs/accuracy.csv has both.",
        "",
        *time_model_table(info),
        "",
        "## Model error against sampling error",
        "",
        "Model error: the RGB model converged against the spectrum converged; no number of "
        "samples removes it. Sampling error: an RGB render against the RGB model converged.",
        "",
        *model_table(rows, facts),
        "",
        "## Anti-aliasing: FLIP against the same model converged (RGB, wavelengths 0)",
        "",
        *aa_table(rows),
        "",
        "## Wavelength count: FLIP against the converged spectrum (aa none)",
        "",
        "At 1 sample:",
        "",
        *wavelength_table(rows, 1),
        "",
        "At 16 samples:",
        "",
        *wavelength_table(rows, 16),
        "",
        "## Is the reference converged?",
        "",
        f"Each reference against the same render at half its samples and half its wavelengths "
        f"({s // 2} × {w // 2}; RGB: {rs // 2} spp). The next doubling changes the image by "
        "less than the last one did, so errors above the floor (10× the last change) are "
        "measured against a reference whose own error is under a tenth of them; errors "
        "below the floor are read as \"at most the floor\".",
        "",
        *convergence_table(facts),
        "",
        "## Pareto fronts",
        "",
        "Per preset, the points no other point beats in both time and error, fastest first "
        "(the `on_*_front` columns of docs/accuracy.csv).",
        "",
        *front_tables(rows),
        "## The tiers on harder materials (the quality=auto table)",
        "",
        "`fine`: twice the pattern's screen frequency (mu_f × 2, or Ashikhmin-Shirley "
        "exponents × 4), as the preset's own material at half the size; `wide`: θ1 = −2π, "
        "θ2 = 2π; `fine-wide`: both.",
        "",
        *variant_table(rows),
        "",
        "![time against error, per preset](accuracy.png)",
        "",
    ])
