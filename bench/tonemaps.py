"""The tone maps measured on the presets' own colours: CIELAB hue shift and chroma loss.

    python bench/tonemaps.py [--size 128] [--exposures 1 4]

Every preset is rendered once at the standard tier (format npy: linear radiance before
the display transform, premultiplied by coverage) and the float64 display twin
(opaline.model.display) tone maps it at each exposure. Over covered pixels, against the
clipped linear colour at the same exposure (the gamut-clipped colour before any tone
map), each tone map's output is measured in CIE L*a*b* (D65):

* hue shift: |Δh_ab| in degrees, mean and p95, over pixels whose reference C*ab > 5
  (below that hue is noise);
* chroma ratio: mean C*ab after ÷ mean C*ab before, over every covered pixel
  (1 keeps the colourfulness, below 1 greys it).

Prints the table and writes bench/results/tonemaps.{md,json}.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import srgb_to_lab  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.model.display import srgb_encode, tonemap  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from opaline.model.presets import all_presets  # noqa: E402
from report import save  # noqa: E402

TONEMAPS = ("none", "reinhard", "aces", "neutral")
HUED = 5.0  # C*ab below which a pixel's hue is not counted


def radiance(local: LocalRenderer, preset: str, size: int) -> np.ndarray:
    """Straight linear colour (× the preset's exposure) of the covered pixels, N×3."""
    request = RenderRequest(preset=preset, width=size, height=size, quality="standard")
    job = local.job(request)
    linear = local.render_array(request).astype(np.float64)
    coverage = linear[..., 3]
    covered = coverage > 0.0
    return linear[covered, :3] / coverage[covered, None] * job.exposure


def lch(linear: np.ndarray, clip: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """L*, C*ab and h_ab (degrees) of linear sRGB colours (in [0, 1] unless not ``clip``)."""
    if clip:
        lab = srgb_to_lab(srgb_encode(linear))
    else:
        import colour

        white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
        xyz = colour.RGB_to_XYZ(linear, colour.RGB_COLOURSPACES["sRGB"], white,
                                apply_cctf_decoding=False)
        lab = colour.XYZ_to_Lab(xyz, white)
    return (lab[..., 0], np.hypot(lab[..., 1], lab[..., 2]),
            np.degrees(np.arctan2(lab[..., 2], lab[..., 1])))


def measure(colours: np.ndarray) -> dict[str, dict[str, float]]:
    """Each tone map's hue shift against the radiance's own hue, and its chroma ratio
    against the clipped colour."""
    # h_ab does not change when a colour is scaled (above L*'s linear toe), so the hue of
    # radiance past 1 is still its hue: clipping a channel is a shift like any other.
    _, reference_chroma, hue = lch(np.maximum(colours, 0.0), clip=False)
    _, chroma, _ = lch(np.clip(colours, 0.0, 1.0))
    hued = reference_chroma > HUED
    out = {}
    for mode in TONEMAPS:
        lightness, c, h = lch(tonemap(colours, mode))
        shift = np.abs((h - hue + 180.0) % 360.0 - 180.0)[hued]
        out[mode] = {
            "hue_mean": float(shift.mean()) if shift.size else 0.0,
            "hue_p95": float(np.percentile(shift, 95.0)) if shift.size else 0.0,
            "chroma_ratio": float(c.mean() / chroma.mean()) if chroma.mean() > 0 else 1.0,
            "chroma_before": float(chroma.mean()), "lightness": float(lightness.mean()),
            "hued_pixels": int(hued.sum()),
        }
    return out


def rows_for(name: str, colours: np.ndarray, exposures: list[float]) -> list[dict]:
    rows = []
    for exposure in exposures:
        for mode, figures in measure(colours * exposure).items():
            rows.append({"preset": name, "exposure": exposure, "tonemap": mode,
                         "pixels": len(colours), **figures})
    return rows


def summary(rows: list[dict]) -> list[str]:
    lines = ["## Every preset's pixels pooled", "",
             "| exposure | tone map | hue shift mean ° | hue shift p95 ° | chroma ratio | "
             "mean L* |", "|---|---|---|---|---|---|"]
    for r in rows:
        if r["preset"] == "all":
            lines.append(f"| {r['exposure']:g} | {r['tonemap']} | {r['hue_mean']:.2f} | "
                         f"{r['hue_p95']:.2f} | {r['chroma_ratio']:.3f} | "
                         f"{r['lightness']:.1f} |")
    return lines + [""]


def per_preset(rows: list[dict], exposure: float) -> list[str]:
    lines = [f"## Per preset, exposure {exposure:g} (hue shift mean / p95 °, chroma ratio)", "",
             "| preset | C*ab before | " + " | ".join(TONEMAPS) + " |",
             "|---|---|" + "---|" * len(TONEMAPS)]
    for preset in dict.fromkeys(r["preset"] for r in rows):
        group = {r["tonemap"]: r for r in rows
                 if r["preset"] == preset and r["exposure"] == exposure}
        cells = [f"{group[m]['hue_mean']:.2f} / {group[m]['hue_p95']:.2f}, "
                 f"{group[m]['chroma_ratio']:.3f}" for m in TONEMAPS]
        before = group[TONEMAPS[0]]["chroma_before"]
        lines.append(f"| {preset} | {before:.1f} | " + " | ".join(cells) + " |")
    return lines + [""]


def table(rows: list[dict], size: int) -> str:
    lines = [f"# Tone maps on the presets' colours (standard tier, {size}²)", "",
             "Hue: |Δh_ab| (CIELAB D65) against the radiance's own hue, over pixels whose "
             f"radiance has C*ab > {HUED:g}. Chroma ratio: mean C*ab after ÷ mean C*ab of the "
             "clipped linear colour at the same exposure, over covered pixels. Mean L*: the "
             "tone-mapped pixels' lightness. Command: `python bench/tonemaps.py`.", ""]
    lines += summary(rows)
    for exposure in dict.fromkeys(r["exposure"] for r in rows):
        lines += per_preset(rows, exposure)
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--exposures", type=float, nargs="+", default=[1.0, 2.0, 4.0, 8.0])
    args = parser.parse_args()
    rows: list[dict] = []
    pooled = []
    with LocalRenderer() as local:
        for name in sorted(all_presets()):
            colours = radiance(local, name, args.size)
            pooled.append(colours)
            rows += rows_for(name, colours, args.exposures)
    rows += rows_for("all", np.concatenate(pooled), args.exposures)
    save("tonemaps", rows, table(rows, args.size))


if __name__ == "__main__":
    main()
