"""The accuracy benchmark's plot, docs/accuracy.png: time against error, per setting and preset."""

from __future__ import annotations

import io
import statistics

from accuracy_report import TIER_ORDER, by_preset

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
