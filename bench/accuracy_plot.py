"""The accuracy benchmark's plot, docs/accuracy.png: per preset, every measured point's time
against its FLIP and its ΔE00 p95, the Pareto front through them, and the tiers on it."""

from __future__ import annotations

import io

from accuracy_front import TIER_ORDER, base_rows, front, tier_point

MARKERS = {"draft": "o", "standard": "s", "high": "^"}


def panel(ax, found: list[dict], key: str, label: str) -> None:
    for aa, colour in (("none", "tab:blue"), ("analytic", "tab:orange")):
        points = [r for r in found if r["aa"] == aa]
        ax.scatter([r["ms"] for r in points], [r[key] for r in points], s=9, color=colour,
                   alpha=0.35, label=f"grid, aa {aa}")
    rgb = [r for r in found if r["wavelengths"] == 0 and r["aa"] == "none"]
    ax.plot([r["ms"] for r in rgb], [r[key] for r in rgb], color="tab:red", lw=0.8, ls="--",
            label="RGB model, 1→32 spp")
    line = front(found, key)
    ax.step([r["ms"] for r in line], [r[key] for r in line], where="post", color="black", lw=1.2,
            label="Pareto front")
    for r in line:
        ax.annotate(f"{r['samples']}×{r['wavelengths']}{'a' if r['aa'] == 'analytic' else ''}",
                    (r["ms"], r[key]), textcoords="offset points", xytext=(3, 3), fontsize=6)
    for tier in TIER_ORDER:
        row = tier_point(found, tier)
        if row is not None:
            ax.plot(row["ms"], row[key], marker=MARKERS[tier], color="black", mfc="gold", ms=9,
                    ls="none", zorder=5, label=tier)
    if key == "flip":
        ax.axhline(0.05, color="grey", lw=0.8, ls=":")
    ax.set(xscale="log", yscale="log", xlabel="ms per image (log)", ylabel=label)
    ax.grid(True, which="both", alpha=0.2)


def plot(rows: list[dict], info: dict) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    presets = list(dict.fromkeys(r["preset"] for r in rows))
    cols = 4
    lines = -(-len(presets) // (cols // 2))
    fig, axes = plt.subplots(lines, cols, figsize=(22, 4.6 * lines), constrained_layout=True,
                             squeeze=False)
    for i, preset in enumerate(presets):
        found = base_rows(rows, preset)
        ax_flip, ax_de = axes[i // 2][2 * (i % 2)], axes[i // 2][2 * (i % 2) + 1]
        panel(ax_flip, found, "flip", "FLIP vs converged spectrum")
        panel(ax_de, found, "de2000_p95", "ΔE00 p95 vs converged spectrum")
        ax_flip.set_title(f"{preset}: FLIP", fontsize=10)
        ax_de.set_title(f"{preset}: ΔE00 p95", fontsize=10)
    axes[0][0].legend(fontsize=7, loc="lower left")
    for ax in axes.flat[2 * len(presets):]:
        ax.set_visible(False)
    fig.suptitle(f"Opaline: time against error over samples × wavelengths × AA, {info['size']}²; "
                 f"labels: samples×wavelengths (a: analytic AA) — {info['cpu']}; {info['gl']}",
                 fontsize=11)
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=90)
    plt.close(fig)
    return out.getvalue()
