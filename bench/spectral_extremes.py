"""θ(λ) beyond 465-612 nm: held constant (what Opaline does) against extended linearly.

    python bench/spectral_extremes.py [--size 96]

At θ = ±2π on four presets, for each rule: how far 32 wavelengths are from 128 at one
sample (the spectrum alone), how far the reference tier is from twice its samples and
wavelengths, and the rotation span over the visible range. Writes
bench/results/spectral_extremes.md and prints it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import flip  # noqa: E402
from opaline.output.files import write_atomic  # noqa: E402

CASES = (("oil-slick", 2 * np.pi, 2 * np.pi), ("cd-rom", -2 * np.pi, 2 * np.pi),
         ("sphere", 2 * np.pi, -2 * np.pi), ("nacre", -2 * np.pi, -2 * np.pi))


def extended(wavelengths, theta1, theta2):
    """The rule before: the end segments of θ(λ) continued straight to 380 and 780 nm."""
    lam = np.asarray(wavelengths, dtype=np.float64)
    xs, ys = np.array([465.0, 549.0, 612.0]), np.array([theta2, theta1, 0.0])
    below = ys[0] + (lam - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])
    above = ys[2] + (lam - xs[2]) * (ys[2] - ys[1]) / (xs[2] - xs[1])
    return np.where(lam < xs[0], below, np.where(lam > xs[2], above, np.interp(lam, xs, ys)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=96)
    args = parser.parse_args()

    from opaline.gl import material_program
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import get_preset
    from opaline.model.request import resolve
    from opaline.model.spectrum import rotation_at, sample_wavelengths
    from opaline.model.tiers import TIERS

    renderer = Renderer(None)

    def draw(preset, theta1, theta2, samples, wavelengths):
        request = RenderRequest(preset=preset, width=args.size, height=args.size,
                                theta1=theta1, theta2=theta2, samples=samples,
                                wavelengths=wavelengths, aa="none", format="png16")
        return renderer.render(resolve(request, get_preset(preset))).display

    ref = TIERS["reference"]
    s, w = ref.samples, ref.wavelengths
    lines = [f"θ(λ) beyond the anchors, {args.size}², FLIP (`python bench/spectral_extremes.py`)",
             "", "| preset | θ1, θ2 | rule | θ span over 380-780 nm (rad) | 32 wl vs 128 wl, 1 spp "
             f"| reference ({s}×{w}) vs {2 * s}×{2 * w} |", "|---|---|---|---|---|---|"]
    try:
        for rule, function in (("held (now)", rotation_at), ("extended (before)", extended)):
            material_program.rotation_at = function  # what the renderer's uniforms call
            for preset, theta1, theta2 in CASES:
                lam = sample_wavelengths(400)
                span = float(np.ptp(function(lam, theta1, theta2)))
                spectrum = flip(draw(preset, theta1, theta2, 1, 128),
                                draw(preset, theta1, theta2, 1, 32))
                converged = flip(draw(preset, theta1, theta2, 2 * s, 2 * w),
                                 draw(preset, theta1, theta2, s, w))
                lines.append(f"| {preset} | {theta1:+.2f}, {theta2:+.2f} | {rule} | {span:.1f} "
                             f"| {spectrum:.4f} | {converged:.4f} |")
                print(lines[-1], flush=True)
    finally:
        material_program.rotation_at = rotation_at
        renderer.release()
    text = "\n".join(lines) + "\n"
    write_atomic(ROOT / "bench" / "results" / "spectral_extremes.md", text.encode())
    print(text)


if __name__ == "__main__":
    main()
