"""Environment light from the map, measured: each tier's error against a converged
brute-force reference of the same integral, and its time.

    OPALINE_ENVIRONMENTS_DIR=DIR python bench/environment_accuracy.py [--size 128]
        [--environments studio sky FILE.hdr] [--cases mirror glossy]

The reference renders the material at the ``reference`` tier (64 samples, 32
wavelengths) with the map read at full resolution for every sample (``brute``: no
prefiltering) and ``--reference-samples`` lobe samples per pixel; it is converged when
it agrees with a render of half as many samples (the ``converged`` column, FLIP). Each
tier then renders as a user gets it (its samples, wavelengths, environment samples,
filtered importance sampling) and is compared with the reference on display images
(bench/metrics.py: FLIP, CIEDE2000). Median-cut lights at the tier's K are measured
beside it, the method they replace. ``grain`` is the image's mean |image − its 3×3
box blur| over the object (display values, 0-1): what few lobe samples a pixel leave as
speckle, beside the reference's own. Prints the table, writes
bench/results/environment_accuracy.{md,json}.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import all_metrics  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from report import save  # noqa: E402

# Materials on the sphere preset, no diffuse: the specular integral is what is measured.
CASES: dict[str, dict[str, Any]] = {
    "mirror": dict(mdf="ashikhmin", ex=1e6, ey=1e6, theta1=0.0, theta2=0.0),
    "glossy": dict(mdf="ashikhmin", ex=300.0, ey=300.0, theta1=0.0, theta2=0.0),
    "broad": dict(mdf="ashikhmin", ex=20.0, ey=20.0, theta1=0.0, theta2=0.0),
    "glossy-aniso": dict(mdf="ashikhmin", ex=100.0, ey=1000.0, theta1=0.0, theta2=0.0),
    "rotation": dict(mdf="ashikhmin", ex=100.0, ey=1000.0, theta1=0.5, theta2=1.0),
    "thin-film": dict(iridescence="thin-film", ex=500.0, ey=500.0, film_ior=1.33,
                      substrate_ior=1.0, film_thickness_min=250.0, film_thickness_max=650.0),
    "thin-film-broad": dict(iridescence="thin-film", ex=20.0, ey=20.0, film_ior=1.68,
                            substrate_ior=1.53, film_thickness_min=350.0,
                            film_thickness_max=550.0),
    "bubble": dict(iridescence="thin-film", ex=4.0, ey=4.0, film_ior=1.33, substrate_ior=1.0,
                   film_thickness_min=0.0, film_thickness_max=1000.0),
    "multipeak": dict(),  # the sphere preset's own material
    # A CD's grating with a lobe broad enough for the brute-force reference's disc
    # samples to converge (the presets' 3000 x 30000 would need millions a pixel).
    "grating": dict(iridescence="grating", mdf="ashikhmin", ex=100.0, ey=100.0,
                    grating_pitch=1.6, grating_orders=3, grating_depth=150.0, f0=0.9),
}
TIERS = ("draft", "standard", "high")


def render(local: LocalRenderer, fields: dict[str, Any], brute: bool = False
           ) -> tuple[np.ndarray, float]:
    job = local.job(RenderRequest(**fields, format="png16"))
    times = []
    for _ in range(1 if brute else 2):
        start = time.perf_counter()
        frame = local.renderer.render(job, brute=brute)
        times.append(time.perf_counter() - start)
    assert frame.display is not None
    return frame.display[..., :3], min(times)


def grain(image: np.ndarray) -> float:
    """Mean |image − 3×3 box blur| where the image is not the background (its corner's
    colour: the sphere does not reach the corners)."""
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    blur = sum(padded[i:i + image.shape[0], j:j + image.shape[1]]
               for i in range(3) for j in range(3)) / 9.0
    covered = np.abs(image - image[0, 0]).max(-1) > 1e-6
    return float(np.abs(image - blur)[covered].mean()) if covered.any() else 0.0


def measure(local: LocalRenderer, case: str, environment: str, size: int, samples: int
            ) -> list[dict[str, Any]]:
    base = dict(preset="sphere", width=size, height=size, environment=environment, kd=0.0,
                environment_background=False, **CASES[case])
    reference, ref_s = render(local, {**base, "quality": "reference",
                                      "environment_samples": samples}, brute=True)
    half, _ = render(local, {**base, "quality": "reference",
                             "environment_samples": samples // 2}, brute=True)
    converged = all_metrics(reference, half)["flip"]
    rows = []
    for tier in TIERS:
        # The same tier's samples and wavelengths with the lighting converged: what the
        # lighting alone costs, apart from the tier's sampling of pixel and spectrum.
        own, _ = render(local, {**base, "quality": tier, "environment_samples": samples},
                        brute=True)
        for method, extra in (("map", {}), ("lights", {"environment_lights": 0})):
            fields = {**base, "quality": tier, **extra}
            if method == "lights":
                fields["environment_lights"] = local.job(
                    RenderRequest(**{**base, "quality": tier})).tier.environment_lights
            image, seconds = render(local, fields)
            rows.append({"case": case, "environment": environment, "tier": tier,
                         "method": method, "ms": seconds * 1e3, "ref_s": ref_s,
                         "converged_flip": converged, **all_metrics(reference, image),
                         "lighting_flip": all_metrics(own, image)["flip"],
                         "grain": grain(image), "reference_grain": grain(reference)})
            print(json.dumps(rows[-1]), flush=True)
    return rows


def table(rows: list[dict[str, Any]], size: int, samples: int) -> str:
    lines = [f"# Environment light against a brute-force reference, {size}²", "",
             f"Reference: the reference tier, the map read unfiltered, {samples} lobe "
             "samples per pixel; `converged` is its FLIP against half as many. Command: "
             "`python bench/environment_accuracy.py`.", "",
             "| case | environment | tier | method | ms | FLIP | lighting FLIP | ΔE00 mean | "
             "ΔE00 p95 | grain (reference) | converged |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['environment']} | {r['tier']} | {r['method']} | "
                     f"{r['ms']:.0f} | {r['flip']:.4f} | {r['lighting_flip']:.4f} | "
                     f"{r['de2000_mean']:.2f} | "
                     f"{r['de2000_p95']:.2f} | {r['grain']:.4f} ({r['reference_grain']:.4f}) | "
                     f"{r['converged_flip']:.4f} |")
    worst = {(t, m): max(r["flip"] for r in rows if r["tier"] == t and r["method"] == m)
             for t in TIERS for m in ("map", "lights")}
    lines += ["", "Worst FLIP over the cases: " + ", ".join(
        f"{t} {m} {v:.3f}" for (t, m), v in worst.items())]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--environments", nargs="+", default=["studio", "sky"])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--reference-samples", type=int, default=2048)
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    with LocalRenderer() as local:
        for environment in args.environments:
            for case in args.cases:
                rows += measure(local, case, environment, args.size, args.reference_samples)
    save("environment_accuracy", rows, table(rows, args.size, args.reference_samples))
    print("median reference seconds", statistics.median(r["ref_s"] for r in rows))


if __name__ == "__main__":
    main()
