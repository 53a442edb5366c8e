"""A film's colour against an exact D65 reference (issue 23): the spectral path converged,
the tiers' wavelengths and the RGB fast path, in ΔE00.

    python bench/white_point.py [--thickness-step 10]

Reference, independent of the project's code: colour-science's ``thin_film_tmm`` (s and p
averaged) at every nm of 360-830, taken to XYZ under D65 by ``msds_to_XYZ`` (an sRGB white
light: sRGB's white is D65), then to linear sRGB and CIELAB (D65) as colour-science does.
Ours: ``thinfilm.film_rgb`` at 128 wavelengths (converged), 16 (standard), 8 (draft) and 0
(the fast path), to CIELAB the same way. Negative channels (out of the sRGB gamut: the
free films' cyans) are clamped on both sides before the comparison, as the shader clamps
its sums. Grid: angles 0-84° by 6°, thickness 0-1200 nm, and films on dielectrics:
(1.33 on 1.0: a soap film), (1.5 on 1.0), (1.33 on 1.5: water on glass), (2.0 on 1.5),
(2.4 on 1.5: titania on glass), (1.5 on 2.4); and oxide films 0-600 nm on gold, copper,
iron and titanium, whose reference is the project's transfer matrix (thin_film_tmm is
inexact under an absorbing medium at oblique incidence). Prints mean, p95 and worst ΔE00
per path, over all and over thick films (800-1200 nm, where few wavelengths alias); writes
bench/results/white_point.{json,md}.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from opaline.model import metals, thinfilm
from opaline.model.multilayer import stack_optics
from opaline.model.params import Material
from report import save  # bench/report.py: run from bench/, it is on the path

FILMS = ((1.33, 1.0), (1.5, 1.0), (1.33, 1.5), (2.0, 1.5), (2.4, 1.5), (1.5, 2.4))
ANGLES = np.arange(0.0, 84.1, 6.0)
PATHS = {"spectral 128": 128, "standard (16)": 16, "draft (8)": 8, "fast (RGB)": 0}
THICK_NM = 800.0
METAL_FILMS = ((1.5, "gold"), (2.4, "gold"), (1.5, "copper"), (2.6, "iron"), (2.4, "titanium"))
METAL_MAX_NM = 600.0  # oxide films on metals: the temper and anodising colours lie below


REFERENCE_NM = np.arange(360.0, 831.0, 1.0)


def dielectric_reflectance(n_film: float, n_sub: float, thickness: np.ndarray) -> np.ndarray:
    """(λ, angle, thickness): colour-science's thin_film_tmm, s and p averaged."""
    from colour.phenomena import interference

    lam = REFERENCE_NM
    n = np.array([np.ones_like(lam), np.full_like(lam, n_film), np.full_like(lam, n_sub)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r, _ = interference.thin_film_tmm(n, thickness, lam, ANGLES)
    result: np.ndarray = r.mean(axis=-1)
    return result


def metal_reflectance(n_film: float, metal: str, thickness: np.ndarray) -> np.ndarray:
    """(λ, angle, thickness) over a tabulated metal: the project's transfer matrix
    (model/multilayer.py, held to colour-science and to the Airy sum in its tests), since
    thin_film_tmm refracts into an absorbing medium inexactly at oblique incidence."""
    lam = REFERENCE_NM[:, None, None]
    cos0 = np.cos(np.radians(ANGLES))[None, :, None]
    nk = metals.metal_index(metal, REFERENCE_NM)[:, None, None]
    optics = stack_optics([n_film], [thickness[None, None, :]], lam, cos0, 1.0, nk)
    return optics.reflectance


def reference_xyz(reflectance: np.ndarray) -> np.ndarray:
    """(…, 3) XYZ (a white's Y = 1) of a reflectance (λ, …) lit by D65, by colour-science."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"]
    shape = colour.SpectralShape(360.0, 830.0, 1.0)
    data = reflectance.reshape(len(REFERENCE_NM), -1)
    msds = colour.MultiSpectralDistributions(data, shape)
    xyz = colour.msds_to_XYZ(msds, cmfs, d65, method="Integration", shape=shape) / 100.0
    return np.asarray(xyz).reshape(*reflectance.shape[1:], 3)


def reference_rgb(reflectance: np.ndarray) -> np.ndarray:
    """(angle, thickness, 3) linear sRGB of a reflectance (λ, angle, thickness) lit by D65,
    by colour-science."""
    import colour

    rgb = colour.XYZ_to_RGB(reference_xyz(reflectance), colour.RGB_COLOURSPACES["sRGB"],
                            apply_cctf_encoding=False)
    return np.asarray(rgb).reshape(*reflectance.shape[1:], 3)


def ours_rgb(n_film: float, under: float | str, thickness: np.ndarray,
             wavelengths: int) -> np.ndarray:
    cos1 = np.cos(np.radians(ANGLES))[:, None]
    if isinstance(under, str):
        material = Material(iridescence="thin-film", substrate="conductor", metal=under)
        n_sub: float | np.ndarray = metals.substrate_for(material, wavelengths)
    else:
        n_sub = under
    return thinfilm.film_rgb(cos1, thickness[None, :], n_film, n_sub, wavelengths)


def delta_e(rgb_a: np.ndarray, rgb_b: np.ndarray) -> np.ndarray:
    import colour

    def lab(rgb: np.ndarray) -> np.ndarray:
        xyz = colour.RGB_to_XYZ(np.clip(rgb, 0.0, None), colour.RGB_COLOURSPACES["sRGB"],
                                apply_cctf_decoding=False)
        return colour.XYZ_to_Lab(xyz, colour.CCS_ILLUMINANTS[
            "CIE 1931 2 Degree Standard Observer"]["D65"])
    return np.asarray(colour.delta_E(lab(rgb_a), lab(rgb_b), method="CIE 2000"))


def measure(step: float, on_metals: bool) -> dict[str, dict[str, float]]:
    top = METAL_MAX_NM if on_metals else 1200.0
    thickness = np.arange(0.0, top + 0.5 * step, step)
    errors: dict[str, list[np.ndarray]] = {name: [] for name in PATHS}
    thick: dict[str, list[np.ndarray]] = {name: [] for name in PATHS}
    for n_film, under in METAL_FILMS if on_metals else FILMS:
        reflectance = (metal_reflectance(n_film, under, thickness) if isinstance(under, str)
                       else dielectric_reflectance(n_film, under, thickness))
        reference = reference_rgb(reflectance)
        for name, wavelengths in PATHS.items():
            de = delta_e(ours_rgb(n_film, under, thickness, wavelengths), reference)
            errors[name].append(de.ravel())
            thick[name].append(de[:, thickness >= THICK_NM].ravel())
    summary = {}
    for name in PATHS:
        every, heavy = np.concatenate(errors[name]), np.concatenate(thick[name])
        summary[name] = {"mean": float(every.mean()), "p95": float(np.percentile(every, 95)),
                         "max": float(every.max())}
        if heavy.size:
            summary[name].update(thick_mean=float(heavy.mean()), thick_max=float(heavy.max()))
    return summary


def table(dielectric: dict[str, dict[str, float]], metal: dict[str, dict[str, float]],
          step: float) -> str:
    lines = [f"Film colour against an exact D65 reference (1 nm, D65, colour-science's "
             f"integration), ΔE00; {len(ANGLES)} angles 0-84°, thickness by {step:g} nm. "
             "Command: `python bench/white_point.py`.", "",
             f"On dielectrics ({len(FILMS)} films, 0-1200 nm; reference colour-science's "
             "thin_film_tmm):", "",
             "| path | mean | p95 | worst | thick (≥ 800 nm) mean | thick worst |",
             "|---|---|---|---|---|---|"]
    for name, s in dielectric.items():
        lines.append(f"| {name} | {s['mean']:.2f} | {s['p95']:.2f} | {s['max']:.2f} | "
                     f"{s['thick_mean']:.2f} | {s['thick_max']:.2f} |")
    lines += ["", f"On metals ({', '.join(f'{n} on {m}' for n, m in METAL_FILMS)}, "
              f"0-{METAL_MAX_NM:g} nm; reference the transfer matrix):", "",
              "| path | mean | p95 | worst |", "|---|---|---|---|"]
    for name, s in metal.items():
        lines.append(f"| {name} | {s['mean']:.2f} | {s['p95']:.2f} | {s['max']:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--thickness-step", type=float, default=10.0)
    args = parser.parse_args()
    dielectric = measure(args.thickness_step, on_metals=False)
    metal = measure(args.thickness_step, on_metals=True)
    save("white_point", {"step_nm": args.thickness_step, "dielectric": dielectric,
                         "metal": metal}, table(dielectric, metal, args.thickness_step))


if __name__ == "__main__":
    main()
