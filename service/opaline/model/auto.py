"""quality=auto: the cheapest measured setting whose error meets the request's budget.

``bench/accuracy.py --write-table`` renders every preset over a grid of samples,
wavelengths and anti-aliasing, for the preset's own material and for harder
variants of it (VARIANTS), scores each point against a converged spectral
reference, and writes ``quality_table.json`` next to this module with the
shader sources' and presets' hashes. A request with ``quality="auto"`` and
``max_flip`` and/or ``max_delta_e`` (CIEDE2000, 95th percentile) gets the
fastest point that meets both on the measured materials that are at least as
hard as its own (``difficulty``), or the reference tier when none is.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

from opaline.model.auto_table import Difficulty, Measure, MeasuredMaterial, Picked, Table
from opaline.model.params import Material
from opaline.model.tiers import TIERS, Measured, Tier, auto_tier

if TYPE_CHECKING:
    from opaline.model.presets import Preset

TABLE_PATH = Path(__file__).resolve().parent / "quality_table.json"
TABLE_SIZE = 128  # the table's renders are TABLE_SIZE² pixels
FALLBACK = "reference"
DEFAULT_MAX_FLIP = 0.05  # quality=auto with no budget given
# A material judged on a harder measured one must meet the budget with this much to spare:
# errors grow with the difficulty measures but not strictly (a spectrum integrated at few
# points depends on where the rotations fall), and on the test materials the error found
# was up to 1.25× the harder material's (docs/accuracy.md, "quality=auto").
MARGIN = 0.7
# Judged on its own measured errors, a material still keeps a little to spare: the table's
# figure is one render against one converged reference, and against another converged image
# it moves by a few thousandths (tempered-steel's 8 × 4 point: 0.0489 against the table's
# 256 × 64 reference, 0.0507 against the accuracy tests' 96 × 32).
EXACT_MARGIN = 0.9
# Nor do few wavelengths: where 4 or 6 rotations fall decides their error (at θ = ±2π most
# land on turns of π, which leave the pattern as it is), so a harder material measured
# with them bounds nothing. A material judged on another one gets this many or more.
MIN_WAVELENGTHS_JUDGED = 8
MEASURES: tuple[Measure, ...] = ("rate", "turn", "span", "brightness")
TWO_PI = 2.0 * math.pi

# Harder materials measured beside each preset's own ("base"): "fine" doubles the
# pattern's screen frequency (as a render at half the size does), "wide" spans the
# whole rotation range, "fine-wide" both.
VARIANTS = ("base", "fine", "wide", "fine-wide")


def variant_material(material: Material, variant: str) -> Material:
    """The preset's material made harder as ``variant`` says."""
    changes: dict[str, float] = {}
    if "fine" in variant.split("-"):
        if material.mdf == "multipeak":
            changes["mu_f"] = min(2.0 * material.mu_f, 1000.0)
        else:  # lobe width goes as 1/sqrt(exponent)
            changes.update(ex=min(4.0 * material.ex, 1e6), ey=min(4.0 * material.ey, 1e6))
    if "wide" in variant.split("-"):
        changes.update(theta1=-TWO_PI, theta2=TWO_PI)
    return material.model_copy(update=changes)


def difficulty(material: Material, width: int, height: int, exposure: float) -> Difficulty:
    """What drives a render's error, each growing with it.

    turn: how fast the pattern changes as it rotates (mu_f·|√α − √β|, or |√ex − √ey|);
    rate: how fast the pattern moves per pixel (the multi-peak phase rate mu_f·√max(α, β)
    or the Ashikhmin-Shirley sharpness √max(ex, ey)), scaled to a TABLE_SIZE² render (a
    larger one spreads the pattern over more pixels; smaller ones are not judged at all);
    span: the rotation range max(0, θ1, θ2) − min(0, θ1, θ2), which sets both the RGB
    model's error and how many wavelengths converge; brightness: ks·exposure, which lifts
    errors above the tone curve's toe. Diffuse terms, Fresnel and the light only add
    smooth shading and are not counted.
    """
    if material.mdf == "multipeak":
        rate = material.mu_f * math.sqrt(max(material.alpha, material.beta))
        # Turning h by dθ moves r by (β − α)·hx·hy/r·dθ: the phase moves about
        # mu_f·|√α − √β| per radian, so the spectrum's rotations smear the bands that fast.
        turn = material.mu_f * abs(math.sqrt(material.alpha) - math.sqrt(material.beta))
    else:
        rate = math.sqrt(max(material.ex, material.ey))
        turn = abs(math.sqrt(material.ex) - math.sqrt(material.ey))
    thetas = (0.0, material.theta1, material.theta2)
    scale = TABLE_SIZE / min(width, height)
    return {"mdf": material.mdf, "rate": rate * scale, "turn": turn,
            "span": max(thetas) - min(thetas), "brightness": material.ks * exposure,
            "size": min(width, height)}


def at_most(easy: Difficulty, hard: Difficulty) -> bool:
    """Is ``easy`` no harder than ``hard`` in every respect (same MDF)?"""
    tol = 1e-9
    return easy["mdf"] == hard["mdf"] and all(
        easy[k] <= hard[k] * (1.0 + 1e-6) + tol for k in MEASURES)


@cache
def load_table(path: Path = TABLE_PATH) -> Table:
    table: Table = json.loads(path.read_text())
    return table


def preset_digest(preset: Preset) -> str:
    """Hash of what the table's numbers depend on in a preset: its scene and its defaults."""
    # mesh_up is a mesh's field, which a preset's defaults do not give (resolve leaves the
    # mesh fields out of them): not dumped, so adding the field left every entry valid.
    defaults = preset.defaults.model_dump(mode="json", exclude={"mesh_up"})
    data = {"scene": preset.scene_key(), "defaults": defaults}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


def pick(preset_name: str, material: Material, width: int, height: int, exposure: float,
         max_flip: float | None, max_delta_e: float | None, table: Table | None = None) -> Tier:
    """The fastest measured setting meeting the targets on the measured materials that stand
    for ``material`` (judged_on; the point-wise worst among them), or the fallback tier's
    setting; as a tier of its own that says why."""
    table = table or load_table()
    entry = table["presets"].get(preset_name)
    wanted = difficulty(material, width, height, exposure)

    def fall_back(why: str) -> Tier:
        fallback = TIERS[FALLBACK]
        return auto_tier(fallback.samples, fallback.wavelengths, fallback.aa,
                         Measured(None, None, f"fallback ({why}): {FALLBACK} tier", max_flip,
                                  max_delta_e))

    if entry is None:
        return fall_back("preset not measured")
    if min(width, height) < table.get("size", TABLE_SIZE):
        # Smaller images alias more than the pattern's rate alone says (silhouettes, normal
        # map texels get relatively bigger): the table does not describe them. They are cheap.
        return fall_back(f"image smaller than the measured {TABLE_SIZE}²")
    judged, exact = judged_on(entry["materials"], material, wanted)
    if not judged:
        return fall_back("material outside the measured ones")
    # The RGB model's error depends on the rotations themselves (θ = 2π is θ = 0 in RGB, a
    # rainbow in the spectrum), so an RGB point is only judged on a material with the same θ.
    same_theta = all(_close(m["theta"], (material.theta1, material.theta2)) for m in judged)
    scale = EXACT_MARGIN if exact else MARGIN
    best = None
    for index, point in enumerate(entry["points"]):
        if point["wavelengths"] == 0 and not same_theta:
            continue
        if 0 < point["wavelengths"] < MIN_WAVELENGTHS_JUDGED and not exact:
            continue
        flip = max(m["flip"][index] for m in judged)
        delta_e = max(m["de2000_p95"][index] for m in judged)
        if (max_flip is None or flip <= scale * max_flip) and (
                max_delta_e is None or delta_e <= scale * max_delta_e):
            # The fastest; of equally fast ones, the more accurate.
            if best is None or (point["ms"], flip) < (best[0]["ms"], best[1]):
                best = (point, flip, delta_e)
    if best is None:
        return fall_back("no measured setting meets the target")
    point, flip, delta_e = best
    names = "+".join(m["variant"] for m in judged)
    return auto_tier(point["samples"], point["wavelengths"], point["aa"],
                     Measured(flip, delta_e, f"measured on {preset_name} ({names})", max_flip,
                              max_delta_e))


def judged_on(measured: list[MeasuredMaterial], material: Material, wanted: Difficulty
              ) -> tuple[list[MeasuredMaterial], bool]:
    """The measured materials whose errors stand for ``material``'s, and whether it is one of
    them (the same material, at the table's size or larger).

    Errors are not monotone in the pattern's rate (twice the frequency can wash the bands
    out to grey in both the render and the reference, and lower the error), so a material
    is judged on the worst of every measured one at the nearest rotation span at or above
    its own, provided its rate, turn and brightness lie within theirs.
    """
    # The same material (its measures at the table's own size), drawn at least that large.
    own: Difficulty = {**wanted, "rate": wanted["rate"] * wanted["size"] / TABLE_SIZE}
    for m in measured:
        d = m["difficulty"]
        if (d["mdf"] == wanted["mdf"] and _close(m["theta"], (material.theta1, material.theta2))
                and _close([d[k] for k in MEASURES], [own[k] for k in MEASURES])):
            return [m], True
    spans = sorted({m["difficulty"]["span"] for m in measured
                    if m["difficulty"]["mdf"] == wanted["mdf"]
                    and m["difficulty"]["span"] >= wanted["span"] * (1.0 - 1e-9)})
    if not spans:
        return [], False
    level = [m for m in measured if m["difficulty"]["mdf"] == wanted["mdf"]
             and _close([m["difficulty"]["span"]], [spans[0]])]
    inside = all(wanted[k] <= max(m["difficulty"][k] for m in level) * (1.0 + 1e-9)
                 for k in ("rate", "turn", "brightness"))
    return (level, False) if inside else ([], False)


def _close(a: Sequence[float], b: Sequence[float]) -> bool:
    return all(abs(x - y) <= 1e-9 * max(1.0, abs(y)) for x, y in zip(a, b, strict=True))


def auto_headers(job: Picked) -> dict[str, str]:
    """Response headers saying what quality=auto picked; empty for other qualities.

    For the HTTP layer: ``response.headers.update(auto_headers(job))``."""
    chosen = job.tier.measured
    if chosen is None:
        return {}
    targets = [f"{name}={value:g}" for name, value in
               (("max_flip", chosen.max_flip), ("max_delta_e", chosen.max_delta_e))
               if value is not None]
    headers = {
        "X-Opaline-Auto-Target": "; ".join(targets),
        "X-Opaline-Auto-Setting":
            f"samples={job.samples}; wavelengths={job.wavelengths}; aa={job.aa}",
        "X-Opaline-Auto-Basis": chosen.basis,
    }
    if chosen.flip is not None:
        headers["X-Opaline-Auto-Flip"] = f"{chosen.flip:.4f}"
        headers["X-Opaline-Auto-DeltaE-P95"] = f"{chosen.delta_e_p95:.2f}"
    return headers


def describe(job: Picked) -> str:
    """One line for the CLI's verbose output."""
    headers = auto_headers(job)
    headers.pop("X-Opaline-Auto-Setting", None)  # the CLI line states the setting already
    return "; ".join(f"{k.removeprefix('X-Opaline-Auto-').lower()}: {v}"
                     for k, v in headers.items())
