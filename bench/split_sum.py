"""Split-sum for the paper's lobes, in its best case: could a prefiltered map replace the
rotation source's lobe samples?

    python bench/split_sum.py [--size 96] [--samples 384]

The route the glTF Sample Viewer and Filament take for GGX, extended to eq. 1's
anisotropic lobe turned per channel: the map convolved with the lobe as seen with the
view along the normal (``n = v = r``, r the mirror direction), read at r with the
channel's turned tangent, times the lobe's albedo at the pixel's own view over its
albedo at normal view. A shader would read that from a table (direction × tangent
angle, three reads a pixel, no lobe samples); here the table is exact (each pixel
convolves at its own r and tangent) and so is the albedo ratio, so what is measured is
the approximation alone, not a table's resolution.

On an orthographic sphere (specular only, F = 1, ks = 1; the map's texels over 50× its
mean capped there, as ``scene.bright`` leaves it), against the exact integral by lobe
samples (R2, shifted per pixel, bilinear reads of level 0), both shown with the same
exposure (the exact image's 99th percentile at 1, sRGB): FLIP. ``converged`` is the
exact image against itself at half its samples. Prints the table, writes
bench/results/split_sum.{md,json}.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "service")]
from metrics import flip  # noqa: E402
from opaline.model.display import srgb_encode  # noqa: E402
from opaline.model.lobe_sampling import R2, sample_ashikhmin  # noqa: E402
from opaline.scene.environments import sky  # noqa: E402
from opaline.scene.studio import studio  # noqa: E402
from report import save  # noqa: E402

# (ex, ey, per-channel θ): bench/environment_accuracy.py's cases and cd-rom-ashikhmin's lobe.
CASES = {"rotation": (100.0, 1000.0, (0.0, 0.5, 1.0)),
         "cd-rom-ashikhmin": (100.0, 10.0, (0.0, 0.2, 0.4)),
         "glossy-aniso": (100.0, 1000.0, (0.0, 0.0, 0.0)),
         "glossy": (300.0, 300.0, (0.0, 0.0, 0.0))}
CAP = 50.0  # scene.bright's: texels over this times the mean become lights
CHUNK = 2000


def read(radiance: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Bilinear read of the equirectangular map (scene.mediancut's convention) along d."""
    rows, cols = radiance.shape[:2]
    elevation = np.arcsin(np.clip(d[..., 1], -1.0, 1.0))
    azimuth = np.mod(np.arctan2(d[..., 2], d[..., 0]), 2 * np.pi)
    r = (np.pi / 2 - elevation) / np.pi * rows - 0.5
    c = azimuth / (2 * np.pi) * cols - 0.5
    r0 = np.clip(np.floor(r), 0, rows - 1).astype(int)
    r1 = np.minimum(r0 + 1, rows - 1)
    fr = np.clip(r - r0, 0.0, 1.0)[..., None]
    c0 = np.floor(c).astype(int)
    fc = (c - c0)[..., None]
    c0 %= cols
    c1 = (c0 + 1) % cols
    top = radiance[r0, c0] * (1 - fc) + radiance[r0, c1] * fc
    bottom = radiance[r1, c0] * (1 - fc) + radiance[r1, c1] * fc
    result: np.ndarray = top * (1 - fr) + bottom * fr
    return result


def lobe_integral(radiance: np.ndarray, n: np.ndarray, v: np.ndarray, tangent: np.ndarray,
                  lobe: tuple[float, float, float], u: np.ndarray,
                  channel: int) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, the mean over its samples ``u`` of L(l)·(n·l)/max(n·l, n·v) in
    ``channel``, with h drawn from eq. 1's lobe turned by θ, and the same with L = 1."""
    ex, ey, theta = lobe
    t = tangent - (tangent * n).sum(-1, keepdims=True) * n
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    b = np.cross(n, t)
    s, _ = sample_ashikhmin(u, ex, ey)
    c, sn = np.cos(theta), np.sin(theta)
    hx, hy = c * s[..., 0] + sn * s[..., 1], c * s[..., 1] - sn * s[..., 0]
    h = hx[..., None] * t[:, None] + hy[..., None] * b[:, None] + s[..., 2:3] * n[:, None]
    l = 2 * (v[:, None] * h).sum(-1, keepdims=True) * h - v[:, None]
    nl = (n[:, None] * l).sum(-1)
    nv = (n * v).sum(-1)[:, None]
    weight = np.where(nl > 0, nl / np.maximum(np.maximum(nl, nv), 1e-9), 0.0)
    return (read(radiance, l)[..., channel] * weight).mean(1), weight.mean(1)


def sphere(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orthographic sphere's pixel mask, normals and tangents (about the up axis)."""
    y, x = np.mgrid[0:size, 0:size]
    px, py = (x + 0.5) / size * 2 - 1, 1 - (y + 0.5) / size * 2
    inside = px ** 2 + py ** 2 < 0.999
    n = np.stack([px, py, np.sqrt(np.maximum(1 - px ** 2 - py ** 2, 0.0))], -1)[inside]
    tangent = np.cross([0.0, 1.0, 0.0], n) + [1e-3, 0.0, 0.0]
    return inside, n, tangent / np.linalg.norm(tangent, axis=-1, keepdims=True)


def images(radiance: np.ndarray, case: tuple[float, float, tuple[float, ...]], size: int,
           samples: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(exact, split-sum) images of the sphere, linear RGB."""
    ex, ey, thetas = case
    inside, n, tangent = sphere(size)
    v = np.broadcast_to([0.0, 0.0, 1.0], n.shape).copy()
    r = 2 * (n * v).sum(-1, keepdims=True) * n - v
    rng = np.random.default_rng(seed)
    exact, split = np.zeros((len(n), 3)), np.zeros((len(n), 3))
    k = (np.arange(samples) + 0.5)[None, :, None]
    for channel, theta in enumerate(thetas):
        for lo in range(0, len(n), CHUNK):
            part = slice(lo, lo + CHUNK)
            u = np.mod(rng.random((len(n[part]), 1, 2)) + k * R2[:2], 1.0)
            lobe = (ex, ey, theta)
            value, albedo = lobe_integral(radiance, n[part], v[part], tangent[part], lobe, u,
                                          channel)
            table, albedo_normal = lobe_integral(radiance, r[part], r[part], tangent[part],
                                                 lobe, u, channel)
            exact[part, channel] = value
            split[part, channel] = table * albedo / np.maximum(albedo_normal, 1e-9)
    out = np.zeros((2, size, size, 3))
    out[0][inside], out[1][inside] = exact, split
    return out[0], out[1]


def capped(radiance: np.ndarray) -> np.ndarray:
    luminance = radiance @ np.array([0.2126, 0.7152, 0.0722])
    limit = CAP * luminance.mean()
    result: np.ndarray = radiance * np.minimum(1.0, limit / np.maximum(luminance, 1e-12))[
        ..., None]
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--samples", type=int, default=384)
    args = parser.parse_args()
    rows = []
    for name, radiance in (("studio", studio()), ("sky", sky())):
        radiance = capped(radiance.astype(np.float64))
        for case, lobe in CASES.items():
            exact, split = images(radiance, lobe, args.size, args.samples, seed=1)
            half, _ = images(radiance, lobe, args.size, args.samples // 2, seed=2)
            scale = 1.0 / np.percentile(exact.max(-1)[exact.sum(-1) > 0], 99)

            def shown(image: np.ndarray, s: float = scale) -> np.ndarray:
                return np.asarray(srgb_encode(np.clip(image * s, 0.0, 1.0)))

            rows.append({"environment": name, "case": case, "lobe": lobe,
                         "split_sum_flip": flip(shown(exact), shown(split)),
                         "converged_flip": flip(shown(exact), shown(half))})
    table = ["| environment | case | ex, ey, θ | split-sum FLIP | converged |", "|---|---|---|---|---|"]
    table += [f"| {r['environment']} | {r['case']} | {r['lobe'][0]:g}, {r['lobe'][1]:g}, "
              f"{'/'.join(f'{t:g}' for t in r['lobe'][2])} | {r['split_sum_flip']:.3f} | "
              f"{r['converged_flip']:.3f} |" for r in rows]
    head = (f"Split-sum in its best case against the exact lobe integral, orthographic sphere "
            f"{args.size}², {args.samples} samples a pixel. Command: `python bench/split_sum.py`.\n\n")
    save("split_sum", {"size": args.size, "samples": args.samples, "rows": rows},
         head + "\n".join(table) + "\n")


if __name__ == "__main__":
    main()
