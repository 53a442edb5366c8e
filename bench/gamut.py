"""How far the colours of films and stacks lie outside sRGB, and what Opaline's handling
of them costs (issue 23), against the exact colour.

    python bench/gamut.py [--thickness-step 10]

Exact colours: reflectance at every nm of 360-830 under D65 (the films' and the metals'
as bench/white_point.py computes them; the stacks' by the transfer matrix), to XYZ by
colour-science. A colour is out of a gamut where a channel of its linear RGB there is
below -1e-4 (of a white's 1). For the colours out of sRGB, each way of showing them is
scored against the exact colour (CIELAB under D65): ΔE00, the hue moved (|Δh_ab|, over
colours with C*ab > 5) and the chroma kept (C*ab shown over exact):

- ``clip``: each linear sRGB channel below 0 set to 0, as the shader does at each
  spectral sum (glsl/lib/material.glsl, thin_film*.glsl, grating.glsl);
- ``desaturate``: the colour moved toward the grey of its own luminance until no channel
  is below 0 (luminance kept): the display's gamut map, ``model/color_space.gamut_map``;
- ``P3 clip``, ``Rec.2020 clip``: the same per-channel clip in the wider primaries, what
  a Display P3 or Rec. 2020 output would show.

Prints a table per family (films on dielectrics, films on metals, stacks) and writes
bench/results/gamut.{json,md}.
"""

from __future__ import annotations

import argparse

import numpy as np

import white_point as wp
from opaline.model import color_space
from opaline.model.multilayer import stack_optics
from report import save  # bench/report.py: run from bench/, it is on the path

SPACES = {"sRGB": "sRGB", "Display P3": "Display P3", "Rec. 2020": "ITU-R BT.2020"}
OUT = -1e-4
# (name, layer indices, thicknesses nm, pairs, substrate): the two stack presets' layers.
STACKS = (("bragg-mirror", (2.4, 1.46), (58.3, 95.9), 6, 1.52),
          ("morpho", (1.56, 1.0), (77.0, 110.0), 7, 1.56))
STACK_SCALES = np.linspace(0.7, 1.3, 25)  # the stop band swept across the visible


def stack_reflectance(indices: tuple[float, float], nm: tuple[float, float], pairs: int,
                      substrate: float) -> np.ndarray:
    """(λ, angle, scale) of (HL)^pairs on ``substrate`` by the transfer matrix."""
    lam = wp.REFERENCE_NM[:, None, None]
    cos0 = np.cos(np.radians(wp.ANGLES))[None, :, None]
    thick = [t * STACK_SCALES[None, None, :] for t in nm] * pairs
    optics = stack_optics(list(indices) * pairs, thick, lam, cos0, 1.0, substrate)
    return optics.reflectance


def to_rgb(xyz: np.ndarray, space: str) -> np.ndarray:
    import colour

    return np.asarray(colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES[SPACES[space]],
                                        apply_cctf_encoding=False))


def to_xyz(rgb: np.ndarray, space: str) -> np.ndarray:
    import colour

    return np.asarray(colour.RGB_to_XYZ(rgb, colour.RGB_COLOURSPACES[SPACES[space]],
                                        apply_cctf_decoding=False))


def shown(xyz: np.ndarray) -> dict[str, np.ndarray]:
    """XYZ each way of handling shows for the exact ``xyz``."""
    srgb = to_rgb(xyz, "sRGB")
    return {"clip": to_xyz(np.maximum(srgb, 0.0), "sRGB"),
            "desaturate": to_xyz(color_space.gamut_map(srgb, "srgb"), "sRGB"),
            "P3 clip": to_xyz(np.maximum(to_rgb(xyz, "Display P3"), 0.0), "Display P3"),
            "Rec.2020 clip": to_xyz(np.maximum(to_rgb(xyz, "Rec. 2020"), 0.0), "Rec. 2020")}


def scores(exact: np.ndarray, got: np.ndarray) -> dict[str, float]:
    import colour

    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    lab_e, lab_g = colour.XYZ_to_Lab(exact, white), colour.XYZ_to_Lab(got, white)
    de = np.asarray(colour.delta_E(lab_e, lab_g, method="CIE 2000"))
    chroma_e, chroma_g = np.hypot(*lab_e[:, 1:].T), np.hypot(*lab_g[:, 1:].T)
    hue = np.degrees(np.arctan2(lab_g[:, 2], lab_g[:, 1]) - np.arctan2(lab_e[:, 2], lab_e[:, 1]))
    hue = np.abs((hue + 180.0) % 360.0 - 180.0)[chroma_e > 5.0]
    return {"de_mean": float(de.mean()), "de_p95": float(np.percentile(de, 95)),
            "de_max": float(de.max()), "hue_mean": float(hue.mean()) if hue.size else 0.0,
            "hue_p95": float(np.percentile(hue, 95)) if hue.size else 0.0,
            "chroma_kept": float(np.median(chroma_g[chroma_e > 5.0] / chroma_e[chroma_e > 5.0]))
            if np.any(chroma_e > 5.0) else 1.0}


def family(reflectances: list[np.ndarray]) -> dict:
    xyz = np.concatenate([wp.reference_xyz(r).reshape(-1, 3) for r in reflectances])
    xyz = xyz[xyz[:, 1] > 1e-4]  # black has no hue to keep
    out = {space: float(np.mean(to_rgb(xyz, space).min(axis=-1) < OUT)) for space in SPACES}
    beyond = xyz[to_rgb(xyz, "sRGB").min(axis=-1) < OUT]
    ways = {name: scores(beyond, got) for name, got in shown(beyond).items()} if len(beyond) else {}
    return {"colours": len(xyz), "out_of": out, "out_of_srgb": ways}


def measure(step: float) -> dict[str, dict]:
    films = np.arange(0.0, 1200.0 + 0.5 * step, step)
    on_metal = np.arange(0.0, wp.METAL_MAX_NM + 0.5 * step, step)
    return {
        "films on dielectrics": family([wp.dielectric_reflectance(n, sub, films)
                                        for n, sub in wp.FILMS]),
        "films on metals": family([wp.metal_reflectance(n, m, on_metal)
                                   for n, m in wp.METAL_FILMS]),
        "stacks": family([stack_reflectance(*s[1:]) for s in STACKS]),
    }


def table(found: dict[str, dict], step: float) -> str:
    lines = [f"Colours of films and stacks outside sRGB, against the exact colour (D65, 1 nm; "
             f"{len(wp.ANGLES)} angles 0-84°, films by {step:g} nm, the stacks' thickness "
             f"×{STACK_SCALES[0]:g}-{STACK_SCALES[-1]:g}). Command: `python bench/gamut.py`.",
             "", "| family | colours | out of sRGB | out of Display P3 | out of Rec. 2020 |",
             "|---|---|---|---|---|"]
    for name, f in found.items():
        o = f["out_of"]
        lines.append(f"| {name} | {f['colours']} | {o['sRGB']:.1%} | {o['Display P3']:.1%} | "
                     f"{o['Rec. 2020']:.1%} |")
    lines += ["", "Over the colours out of sRGB, each way of showing them against the exact "
              "colour (ΔE00; |Δh_ab| in degrees; chroma shown over exact, median):", "",
              "| family | way | ΔE00 mean | p95 | worst | |Δh| mean | p95 | chroma kept |",
              "|---|---|---|---|---|---|---|---|"]
    for name, f in found.items():
        for way, s in f["out_of_srgb"].items():
            lines.append(f"| {name} | {way} | {s['de_mean']:.2f} | {s['de_p95']:.2f} | "
                         f"{s['de_max']:.2f} | {s['hue_mean']:.1f} | {s['hue_p95']:.1f} | "
                         f"{s['chroma_kept']:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--thickness-step", type=float, default=10.0)
    args = parser.parse_args()
    found = measure(args.thickness_step)
    save("gamut", {"step_nm": args.thickness_step, **found}, table(found, args.thickness_step))


if __name__ == "__main__":
    main()
