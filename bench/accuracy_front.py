"""Pareto fronts of the accuracy grid, and where the quality tiers sit on them."""

from __future__ import annotations

TIER_ORDER = ("draft", "standard", "high")


def point_of(row: dict) -> tuple:
    """A row's point: (samples, wavelengths, aa)."""
    return row["samples"], row["wavelengths"], row["aa"]


def base_rows(rows: list[dict], preset: str) -> list[dict]:
    return [r for r in rows if r["preset"] == preset and r["variant"] == "base"]


def front(rows: list[dict], key: str) -> list[dict]:
    """The points no other point beats in both time and ``key`` error, fastest first."""
    best, out = float("inf"), []
    for row in sorted(rows, key=lambda r: (r["ms"], r[key])):
        if row[key] < best:
            out.append(row)
            best = row[key]
    return out


def best_within(rows: list[dict], key: str, ms: float) -> float:
    """The smallest ``key`` error any point reaches in at most ``ms``."""
    return min((r[key] for r in rows if r["ms"] <= ms), default=float("inf"))


def tier_setting(preset: str, tier: str) -> tuple[int, int, str]:
    """(samples, wavelengths, aa) a request for ``tier`` on ``preset`` resolves to: a
    film's wavelengths are the tier's for its colour source (model/tiers.py)."""
    from opaline.model.params import RenderRequest
    from opaline.model.request import resolve

    job = resolve(RenderRequest(preset=preset, quality=tier))
    return job.samples, job.wavelengths, job.aa


def tier_point(rows: list[dict], tier: str) -> dict | None:
    if not rows:
        return None
    samples, wavelengths, want_aa = tier_setting(rows[0]["preset"], tier)
    # "analytic" compiles nothing for the Ashikhmin-Shirley MDF: its image is aa none's.
    for aa in (want_aa, "none"):
        found = next((r for r in rows if r["samples"] == samples
                      and r["wavelengths"] == wavelengths and r["aa"] == aa), None)
        if found is not None:
            return found
    return None


def placement(rows: list[dict]) -> list[dict]:
    """Per preset and tier: its time, time over draft's, FLIP and ΔE00 p95, and the best FLIP
    any measured point reaches in the same time (the front under it)."""
    out = []
    for preset in dict.fromkeys(r["preset"] for r in rows):
        found = base_rows(rows, preset)
        draft = tier_point(found, "draft")
        for tier in TIER_ORDER:
            row = tier_point(found, tier)
            if row is None or draft is None:
                continue
            out.append({"preset": preset, "tier": tier, "ms": row["ms"],
                        "ratio": row["ms"] / draft["ms"], "flip": row["flip"],
                        "de2000_p95": row["de2000_p95"],
                        "front_flip": best_within(found, "flip", row["ms"]),
                        "on_front": row in front(found, "flip")})
    return out
