"""The accuracy benchmark's measurements: a grid of settings per preset, timed and scored
against converged references that are cached on disk.

A point is (samples, wavelengths, aa). Every point of the preset's own material
("base") is timed; the harder variants of model/auto.py reuse those times (a
material's numbers do not change the program) and are only scored. The
references: the spectrum converged (REFERENCE, stratified wavelengths, aa none)
and the RGB model converged (RGB_REFERENCE); each is also rendered at half its
samples and wavelengths, and the FLIP between the two is the convergence check.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import time
from pathlib import Path

import numpy as np

from metrics import all_metrics, flip

RESULTS = Path(__file__).resolve().parent / "results" / "references"
SAMPLES = (1, 2, 4, 8, 16, 32)
WAVELENGTHS = (0, 3, 4, 6, 8, 12, 16, 32)
TABLE_WAVELENGTHS = (0, 4, 8, 16, 32)  # the variants' (and the shipped table's) columns
REFERENCE = (256, 64)  # samples, wavelengths: 16384 points of the spectrum per pixel
RGB_REFERENCE = (512, 0)


def grid(mdf: str, wavelengths=WAVELENGTHS) -> list[tuple[int, int, str]]:
    """Every point; the analytic filter only where it compiles (the multi-peak MDF)."""
    modes = ("none", "analytic") if mdf == "multipeak" else ("none",)
    return [(s, w, aa) for aa in modes for w in wavelengths for s in SAMPLES]


class Bench:
    """One renderer, one size; renders (and times) points of a preset and material."""

    def __init__(self, size: int, renderer=None) -> None:
        from opaline.gl.renderer import Renderer

        self.size = size
        self.renderer = renderer or Renderer(None)
        # (preset, material, point) → the programs rendering it compiles (``compiled``):
        # a reference's cache key and the table's stamps ask for the same points.
        self.programs_at: dict[tuple[str, str, tuple], frozenset] = {}

    def job(self, preset, material, samples: int, wavelengths: int, aa: str,
            size: int | None = None):
        from opaline.model.params import MIN_WAVELENGTHS, RenderRequest
        from opaline.model.request import resolve

        size = size or self.size
        fields = material.model_dump()
        # The grid measures counts the API refuses (1-3 wavelengths), to show why it does.
        allowed = max(wavelengths, MIN_WAVELENGTHS) if wavelengths else 0
        request = RenderRequest(preset=preset.name, width=size, height=size, samples=samples,
                                wavelengths=allowed, aa=aa, format="png16",
                                quality="reference", **fields)
        return dataclasses.replace(resolve(request, preset), wavelengths=wavelengths)

    def image(self, preset, material, point) -> np.ndarray:
        return self.renderer.render(self.job(preset, material, *point), preset).display

    def timed(self, preset, material, point, repeats: int = 3) -> tuple[np.ndarray, float]:
        """The display image and the fastest of ``repeats`` warm renders in ms (the machine is
        shared: the minimum is the draw least disturbed by other work)."""
        self.renderer.render(self.job(preset, material, *point, size=16), preset)  # compile
        job = self.job(preset, material, *point)
        best, image = float("inf"), None
        for _ in range(repeats):
            start = time.perf_counter()
            image = self.renderer.render(job, preset).display
            best = min(best, time.perf_counter() - start)
        return image, 1e3 * best

    def release(self) -> None:
        self.renderer.release()


def compiled(bench: Bench, preset, material, points) -> list:
    """The program variants (gl/shaders.py's ProgramKey) that rendering ``points`` compiles,
    found by rendering each at 16², the least the API takes (a variant does not depend on
    the image's size), once a bench: a point's programs are kept (``Bench.programs_at``)."""
    found: set = set()
    for point in points:
        key = (preset.name, material.model_dump_json(), tuple(point))
        if key not in bench.programs_at:
            bench.programs_at[key] = frozenset(_render_recorded(bench, preset, material, point))
        found.update(bench.programs_at[key])
    return sorted(found)


def _render_recorded(bench: Bench, preset, material, point) -> set:
    programs = bench.renderer.programs
    programs.record = seen = set()
    try:
        bench.renderer.render(bench.job(preset, material, *point, size=16), preset)
    finally:
        programs.record = None
    return seen


def reference_points(rgb: bool) -> list[tuple[int, int, str]]:
    """The references' settings (``references``): each converged one and its half."""
    settings = [REFERENCE, (REFERENCE[0] // 2, REFERENCE[1] // 2)]
    if rgb:
        settings += [RGB_REFERENCE, (RGB_REFERENCE[0] // 2, RGB_REFERENCE[1])]
    return [(s, w, "none") for s, w in settings]


def measured_programs(bench: Bench, preset, variants: list[str]) -> list:
    """Every program variant a preset's measurement (``measure``, its own material and
    ``variants``) compiles, references included: the table is stamped with their digest."""
    from opaline.model.auto import variant_material
    from opaline.model.request import resolve

    base = resolve(_request(preset.name), preset).material
    found: set = set()
    for variant in ["base", *variants]:
        material = variant_material(base, variant)
        points = grid(material.mdf, WAVELENGTHS if variant == "base" else TABLE_WAVELENGTHS)
        found.update(compiled(bench, preset, material,
                              [*points, *reference_points(variant == "base")]))
    return sorted(found)


def cache_path(bench: Bench, preset, material, samples: int, wavelengths: int) -> Path:
    from opaline import __version__
    from opaline.gl.variant_source import variant_digest

    # The programs the reference compiles, as they compile (an edit elsewhere, or to a
    # comment, keeps it); the version too: the colour weights (D65 since 0.2.0) live in
    # Python, not the shaders.
    programs = compiled(bench, preset, material, [(samples, wavelengths, "none")])
    key = json.dumps({"scene": preset.scene_key(), "material": material.model_dump(mode="json"),
                      "size": bench.size, "shaders": variant_digest(programs),
                      "version": __version__}, sort_keys=True)
    digest = hashlib.sha256(key.encode()).hexdigest()[:12]
    return RESULTS / f"{preset.name}-{bench.size}-{samples}x{wavelengths}-{digest}.npy"


def reference(bench: Bench, preset, material, samples: int, wavelengths: int) -> np.ndarray:
    """A brute-force image (aa none), from the disk cache when the programs it compiles,
    scene, material and size are the same."""
    path = cache_path(bench, preset, material, samples, wavelengths)
    if path.exists():
        return np.load(path)
    image = bench.image(preset, material, (samples, wavelengths, "none"))
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, image)
    return image


def references(bench: Bench, preset, material, rgb: bool) -> dict:
    """The converged spectrum (and RGB model), and how much the last doubling changed them."""
    s, w = REFERENCE
    out = {"spectral": reference(bench, preset, material, s, w)}
    half = reference(bench, preset, material, s // 2, w // 2)
    out["conv_flip"] = flip(out["spectral"], half)
    out["conv_de2000_p95"] = all_metrics(out["spectral"], half)["de2000_p95"]
    if rgb:
        s, w = RGB_REFERENCE
        out["rgb"] = reference(bench, preset, material, s, w)
        out["rgb_conv_flip"] = flip(out["rgb"], reference(bench, preset, material, s // 2, w))
        model = all_metrics(out["spectral"], out["rgb"])
        out.update({f"model_{k}": v for k, v in model.items()})
    return out


def measure(bench: Bench, preset, variant: str, times: dict | None) -> tuple[list[dict], dict]:
    """Rows for one preset and material variant, and its reference facts. ``times`` (base
    only: None) maps a point to its measured ms; it is filled in when None."""
    from opaline.model.auto import difficulty, variant_material
    from opaline.model.request import resolve

    base = resolve(_request(preset.name), preset).material
    material = variant_material(base, variant)
    refs = references(bench, preset, material, rgb=variant == "base")
    points = grid(material.mdf, WAVELENGTHS if times is None else TABLE_WAVELENGTHS)
    measured_times = times if times is not None else {}
    rows = []
    for point in points:
        if times is None:
            image, ms = bench.timed(preset, material, point)
            measured_times[point] = ms
        else:
            image = bench.image(preset, material, point)
        row = {"preset": preset.name, "variant": variant, "samples": point[0],
               "wavelengths": point[1], "aa": point[2], "ms": measured_times[point],
               **all_metrics(refs["spectral"], image)}
        if point[1] == 0 and "rgb" in refs:
            row["flip_sampling"] = flip(refs["rgb"], image)
        rows.append(row)
    facts = {k: v for k, v in refs.items() if not isinstance(v, np.ndarray)}
    facts.update(preset=preset.name, variant=variant,
                 difficulty=difficulty(material, bench.size, bench.size, 1.0),
                 material=material.model_dump(mode="json"))
    return rows, {"facts": facts, "times": measured_times}


def _request(name: str):
    from opaline.model.params import RenderRequest

    return RenderRequest(preset=name, quality="draft")


def paired_ratios(bench: Bench, preset, points: list[tuple], baseline: tuple,
                  pairs: int = 5) -> dict[tuple, float]:
    """Time of each point over ``baseline``'s, from renders in alternating pairs (median of the
    pairs' ratios): load from other work on a shared machine hits both halves of a pair."""
    from opaline.model.request import resolve

    material = resolve(_request(preset.name), preset).material
    bench.timed(preset, material, baseline, 1)
    out = {}
    for point in points:
        bench.timed(preset, material, point, 1)
        ratios = []
        for _ in range(pairs):
            _, base_ms = bench.timed(preset, material, baseline, 1)
            _, ms = bench.timed(preset, material, point, 1)
            ratios.append(ms / base_ms)
        out[point] = sorted(ratios)[len(ratios) // 2]
    return out


def fit_times(rows: list[dict]) -> dict[str, list[float]]:
    """Replace each row's ``ms`` by a per-preset cost model fitted to all its measured times
    (kept as ``ms_measured``): ms = a + b·samples + (c + d·[analytic])·samples·max(wl, 3),
    non-negative least squares on relative error. On a shared 2-core machine one point's
    fastest-of-3 still scatters by 10-50 %; the model ranks points by what they cost, not by
    what else ran meanwhile. Returns the coefficients (a, b, c, d) per preset."""
    from scipy.optimize import nnls

    coefficients = {}
    for preset in dict.fromkeys(r["preset"] for r in rows):
        mine = [r for r in rows if r["preset"] == preset]
        for r in mine:
            r.setdefault("ms_measured", r["ms"])
        base = [r for r in mine if r["variant"] == "base"]
        design = np.array([_terms(r) for r in base])
        measured = np.array([r["ms_measured"] for r in base])
        coef, _ = nnls(design / measured[:, None], np.ones(len(base)))
        coefficients[preset] = [float(c) for c in coef]
        for r in mine:
            r["ms"] = float(np.dot(_terms(r), coef))
    return coefficients


def _terms(row: dict) -> list[float]:
    work = row["samples"] * max(row["wavelengths"], 3)
    return [1.0, row["samples"], work, work * (row["aa"] == "analytic")]
