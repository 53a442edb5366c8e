"""Request resolution: preset defaults, then the request's fields, then the tier.

Produces a ``Job``: every value concrete, nothing optional, and a canonical
JSON form whose hash (with the shader sources and the version) is the cache
key for the encoded image.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from typing import Any

from opaline import __version__
from opaline.errors import PublicError
from opaline.model.auto import DEFAULT_MAX_FLIP, pick
from opaline.model.params import MATERIAL_FIELDS, Material, RenderFields, RenderRequest
from opaline.model.presets import Preset, get_preset
from opaline.model.scene_fields import MESH_FIELDS
from opaline.model.tiers import TIERS, Tier
from opaline.resources import sources_digest
from opaline.scene.environments import NO_ENVIRONMENT

BASE_DEFAULTS = {
    "width": 256,
    "height": 256,
    "format": "png",
    "transparent": False,
    "quality": "standard",
    "exposure": 1.0,
    "tonemap": "neutral",
    "color_space": "srgb",
}


class CostError(PublicError, ValueError):
    """The request would cost more than the configured budget."""

    status, reason = 422, "cost"


@dataclass(frozen=True)
class Job:
    """A fully resolved render: what the renderer needs and nothing else."""

    preset: str
    material: Material
    width: int
    height: int
    format: str
    transparent: bool
    tier: Tier  # the quality tier, or quality=auto's pick; the three below may override it
    samples: int
    wavelengths: int
    aa: str
    exposure: float
    tonemap: str
    light_azimuth: float | None
    light_elevation: float | None
    camera_azimuth: float | None = None
    camera_elevation: float | None = None
    camera_distance: float | None = None
    environment: str | None = None
    environment_rotation: float | None = None
    environment_intensity: float | None = None
    environment_lights: int | None = None
    environment_samples: int | None = None
    environment_background: bool | None = None
    environment_blur: float | None = None
    color_space: str = "srgb"

    @property
    def quality(self) -> str:
        return self.tier.name

    @property
    def environment_count(self) -> int:
        """K: the lights an environment becomes, the job's own count or its tier's."""
        return self.environment_lights or self.tier.environment_lights

    @property
    def environment_sample_count(self) -> int:
        """Lobe samples (a grating: reads of its orders' curve) per pixel that read the
        environment map, the job's or its tier's."""
        if self.environment_samples:
            return self.environment_samples
        material = self.material
        if material.iridescence == "rotation" and material.mdf == "ashikhmin":
            return self.tier.environment_samples_rotation
        if material.iridescence == "grating":
            return self.tier.environment_samples_grating
        return self.tier.environment_samples

    @property
    def cost(self) -> int:
        return self.width * self.height * self.samples * max(self.wavelengths, 3)

    def canonical(self) -> dict[str, Any]:
        # Field by field: asdict() deep-copied the material only for it to be dumped again
        # (a twentieth of the service's own time on a cache miss).
        # The tier by its name, where the field has always stood (answers keep their order).
        data = {("quality" if name == "tier" else name): getattr(self, name)
                for name in self.__dataclass_fields__}
        data["material"] = self.material.model_dump(mode="json")
        data["quality"] = self.tier.name
        if self.tier.measured is not None:  # tier jobs keep the keys they had before auto
            data["auto"] = {**self.tier.render_settings(self.material),
                            **asdict(self.tier.measured)}
        return data

    def cache_key(self, scene_key: str) -> str:
        """``scene_key`` is ``Preset.scene_key()``: a job names its preset, not the scene it
        draws, so an edited preset file must give new keys."""
        return content_key({"job": self.canonical(), "scene": scene_key})


def content_key(payload: dict[str, object]) -> str:
    """Hash of what an image depends on, with the shader sources and the version, so a
    changed shader or release never answers from an old image."""

    stamped = {**payload, "shaders": sources_digest(), "version": __version__}
    return hashlib.sha256(json.dumps(stamped, sort_keys=True).encode()).hexdigest()[:32]


def preset_fields(preset: Preset) -> dict[str, Any]:
    """What a request on ``preset`` starts from: the built-in defaults, then the preset's."""
    fields: dict[str, Any] = dict(BASE_DEFAULTS)
    fields.update(preset.defaults.model_dump(exclude_none=True, exclude=set(MESH_FIELDS)))
    return fields


def preset_material(preset: Preset) -> Material:
    """The material a request on ``preset`` that sets no material field draws."""
    fields = preset_fields(preset)
    return Material(**{k: fields[k] for k in MATERIAL_FIELDS if k in fields})


def resolve(request: RenderRequest | RenderFields, preset: Preset | None = None) -> Job:
    """Merge built-in defaults, the preset's defaults, the request's fields and the tier."""
    if preset is None:
        preset = get_preset(getattr(request, "preset", "sphere"))
    fields = dict(preset_fields(preset))
    fields.update(unsigned_zeros(request.model_dump(exclude_none=True,
                                                    exclude={"preset", *MESH_FIELDS})))
    targets = {k: fields.pop(k, None) for k in ("max_flip", "max_delta_e")}
    if "quality" not in request.model_fields_set and any(v is not None for v in targets.values()):
        fields["quality"] = "auto"  # an error budget asks for auto unless a tier is named
    if fields.get("environment") == NO_ENVIRONMENT:
        fields["environment"] = None
    material = Material(**{k: fields.pop(k) for k in MATERIAL_FIELDS if k in fields})
    quality = fields.pop("quality")
    tier = pick_for(preset.name, material, fields, **targets) if quality == "auto" else TIERS[quality]
    for name, value in tier.render_settings(material).items():
        fields.setdefault(name, value)
    if fields["format"] == "auto":  # the HTTP service negotiates before resolving
        fields["format"] = "png"
    return Job(
        preset=preset.name,
        material=material,
        tier=tier,
        light_azimuth=fields.pop("light_azimuth", None),
        light_elevation=fields.pop("light_elevation", None),
        **fields,
    )


def unsigned_zeros(fields: dict[str, Any]) -> dict[str, Any]:
    """-0.0 as 0.0: the renderer cannot tell them apart, so one image has one key (and one
    canonical URL, whose spelling has no sign on zero)."""
    def clean(value: Any) -> Any:
        if isinstance(value, float):
            return value + 0.0
        if isinstance(value, tuple | list):
            return type(value)(clean(v) for v in value)
        return value
    return {name: clean(value) for name, value in fields.items()}


def pick_for(preset: str, material: Material, fields: dict[str, Any], max_flip: float | None,
             max_delta_e: float | None) -> Tier:
    """quality=auto's choice for this preset, material and size (model/auto.py); with no
    budget given, FLIP 0.05."""
    if max_flip is None and max_delta_e is None:
        max_flip = DEFAULT_MAX_FLIP
    return pick(preset, material, fields["width"], fields["height"], fields["exposure"],
                max_flip, max_delta_e)


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
