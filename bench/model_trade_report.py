"""Table, CSV and plot of bench/model_trade.py's rows."""

from __future__ import annotations

import csv
import io

FLOOR = 0.05  # ΔE00 below this is drawn at it (log axis)
COLUMNS = ("preset", "model", "setting", "seconds", "de_object", "de_bright", "flip")


def to_csv(rows: list[dict]) -> bytes:
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow([*COLUMNS, "fit"])
    for row in rows:
        fit = row.get("fit")
        fitted = " ".join(f"{k}={v:g}" for k, v in fit.items()) if fit else ""
        writer.writerow([*(_value(row[c]) for c in COLUMNS), fitted])
    return out.getvalue().encode()


def _value(value):
    return f"{value:.4g}" if isinstance(value, float) else value


def to_markdown(rows: list[dict], info: dict) -> str:
    lines = [
        "# The paper's model against the physics it imitates",
        "",
        f"Measured by `python bench/model_trade.py` on {info['date']}, {info['size']}² images, "
        f"{info['gl']}. Ground truth: the physical model at 64 samples and 128 wavelengths "
        "(3.1 nm bins). Errors against it: CIEDE2000 mean over the object and over where the "
        "colour source shows (pixels whose ground truth differs by more than 0.05 from the "
        "scene without specular: the streak, the bands), and mean FLIP over the image. The "
        "paper's model is rendered on the same scene at its reference tier, with the figure "
        "parameters of the paired paper preset and with mu_f, alpha, beta, theta1, theta2 and "
        "ks fitted by least squares to the ground truth (ks too, or brightness alone would "
        "decide the fit). docs/physics.md explains the physical models. Times are warm "
        f"medians on a shared machine (5-minute load average {info.get('load', '?')} at the "
        "end of the run): compare them within a preset, not across runs; the errors are "
        "deterministic.",
        "",
        "| preset | model | setting | time (s) | ΔE00 object | ΔE00 streak / bands | FLIP |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['preset']} | {row['model']} | {row['setting']} | {row['seconds']:.3f} | "
            f"{row['de_object']:.1f} | {row['de_bright']:.1f} | {row['flip']:.3f} |")
    fits = [row for row in rows if row.get("fit")]
    if fits:
        lines += ["", "Fitted parameters of the paper's model:", ""]
        for row in fits:
            values = ", ".join(f"{k} {v:g}" for k, v in row["fit"].items())
            lines.append(f"- {row['preset']}: {values}")
    lines += ["", "![time against error](model_trade.png)", ""]
    return "\n".join(lines)


def plot(rows: list[dict], info: dict) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    presets = list(dict.fromkeys(row["preset"] for row in rows))
    fig, ax = plt.subplots(figsize=(8, 5), dpi=110)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, name in enumerate(presets):
        colour = colours[i % len(colours)]
        tiers = [r for r in rows if r["preset"] == name and r["model"] == "physical"
                 and r["setting"] != "ground truth"]
        ax.plot([r["seconds"] for r in tiers], [max(r["de_bright"], FLOOR) for r in tiers], "o-",
                color=colour, label=f"{name}: physical tiers")
        for r in tiers:
            ax.annotate(r["setting"], (r["seconds"], max(r["de_bright"], FLOOR)), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
        for r in rows:
            if r["preset"] == name and r["model"] == "paper":
                marker = "s" if r["setting"].startswith("figure") else "^"
                ax.plot(r["seconds"], max(r["de_bright"], FLOOR), marker, color=colour, mfc="none", ms=9)
    ax.plot([], [], "ks", mfc="none", label="paper's model, figure parameters")
    ax.plot([], [], "k^", mfc="none", label="paper's model, least-squares fit")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(FLOOR * 0.7, 100.0)
    ax.set_xlabel(f"render time, s ({info['size']}², {info['gl']})")
    ax.set_ylabel(f"CIEDE2000 mean where the colour shows (floor {FLOOR})")
    ax.set_title("Physical model per tier against the paper's model at its best")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
