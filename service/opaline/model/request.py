"""Request resolution: preset defaults, then the request's fields, then the tier.

Produces a ``Job``: every value concrete, nothing optional, and a canonical
JSON form whose hash (with the shader sources and the version) is the cache
key for the encoded image.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass

from opaline import __version__
from opaline.model.params import MATERIAL_FIELDS, Material, RenderFields, RenderRequest
from opaline.model.presets import Preset, get_preset
from opaline.resources import sources_digest

# What each quality tier means; a request may override any field of it.
TIERS: dict[str, dict[str, object]] = {
    # Chosen from docs/accuracy.md: the analytic band-limit helps a single sample on
    # high-frequency presets, but over supersamples it blurs (most on normal maps,
    # where the phase footprint jumps at platelet edges), so only draft uses it.
    "draft": {"samples": 1, "wavelengths": 0, "aa": "analytic"},
    "standard": {"samples": 4, "wavelengths": 0, "aa": "none"},
    "high": {"samples": 16, "wavelengths": 16, "aa": "none"},
    # Converged target of the benchmark: brute force, no analytic approximation.
    "reference": {"samples": 64, "wavelengths": 32, "aa": "none"},
}

BASE_DEFAULTS = {
    "width": 256,
    "height": 256,
    "format": "png",
    "transparent": False,
    "quality": "standard",
    "exposure": 1.0,
    "tonemap": "aces",
}


class CostError(ValueError):
    """The request would cost more than the configured budget."""


@dataclass(frozen=True)
class Job:
    """A fully resolved render: what the renderer needs and nothing else."""

    preset: str
    material: Material
    width: int
    height: int
    format: str
    transparent: bool
    quality: str
    samples: int
    wavelengths: int
    aa: str
    exposure: float
    tonemap: str
    light_azimuth: float | None
    light_elevation: float | None

    @property
    def cost(self) -> int:
        return self.width * self.height * self.samples * max(self.wavelengths, 3)

    def canonical(self) -> dict:
        data = asdict(self)
        data["material"] = self.material.model_dump(mode="json")
        return data

    def cache_key(self, scene_key: str) -> str:
        """``scene_key`` is ``Preset.scene_key()``: a job names its preset, not the scene it
        draws, so an edited preset file must give new keys."""
        return content_key({"job": self.canonical(), "scene": scene_key})


def content_key(payload: dict) -> str:
    """Hash of what an image depends on, with the shader sources and the version, so a
    changed shader or release never answers from an old image."""

    stamped = {**payload, "shaders": sources_digest(), "version": __version__}
    return hashlib.sha256(json.dumps(stamped, sort_keys=True).encode()).hexdigest()[:32]


def resolve(request: RenderRequest | RenderFields, preset: Preset | None = None) -> Job:
    """Merge built-in defaults, the preset's defaults and the request's fields."""
    if preset is None:
        preset = get_preset(getattr(request, "preset", "sphere"))
    fields: dict = dict(BASE_DEFAULTS)
    fields.update(preset.defaults.model_dump(exclude_none=True))
    fields.update(request.model_dump(exclude_none=True, exclude={"preset"}))
    tier = TIERS[fields["quality"]]
    for name, value in tier.items():
        fields.setdefault(name, value)
    if fields["format"] == "auto":  # the HTTP service negotiates before resolving
        fields["format"] = "png"
    material = Material(**{k: fields.pop(k) for k in MATERIAL_FIELDS if k in fields})
    return Job(
        preset=preset.name,
        material=material,
        light_azimuth=fields.pop("light_azimuth", None),
        light_elevation=fields.pop("light_elevation", None),
        **fields,
    )


def check_cost(job: Job, budget: int) -> None:
    factors = f"{job.width}×{job.height}×{job.samples}×{max(job.wavelengths, 3)}"
    _within_budget(job.cost, "width×height×samples×max(wavelengths, 3)", factors, budget,
                   "the size, samples or wavelengths")


def check_plot_cost(size: int, wavelengths: int, budget: int) -> None:
    """The MDF plot's cost: one sample per pixel of a size×size plot."""
    cost = size * size * max(wavelengths, 3)
    _within_budget(cost, "size²×max(wavelengths, 3)", f"{size}²×{max(wavelengths, 3)}", budget,
                   "the size or wavelengths")


def _within_budget(cost: int, formula: str, factors: str, budget: int, advice: str) -> None:
    if cost > budget:
        raise CostError(
            f"cost={cost} ({formula} = {factors}) is over the budget of {budget}: "
            f"lower {advice}"
        )
