"""One URL per image: the canonical GET query of a prepared job, as a projection of it.

A cache in front of several replicas (nginx, a CDN) keys on the URL, so two
spellings of one request would be rendered twice. The canonical form keeps only
the fields that differ from what the preset and the job's tier would give, in
one fixed order, floats in their shortest round-trip spelling. It is read off
the finished job and nothing is resolved again: the job's values are already
the ones its query reads back to (``resolve`` folds -0.0 into 0.0, the one
value whose spelling loses a distinction the renderer cannot see), which
``tests/pipeline`` checks by reading queries back.
"""

from __future__ import annotations

from typing import Any
from urllib.parse import urlencode

from opaline.model.params import MATERIAL_FIELDS, RenderRequest
from opaline.model.presets import Preset
from opaline.model.request import Job, preset_fields, preset_material
from opaline.model.scene_fields import MESH_FIELDS
from opaline.scene.environments import NO_ENVIRONMENT

RENDER_PATH = "/v1/render"
# Fields of the request that the Job does not keep: the mesh (part of the scene) and
# quality=auto's error budget (the Job keeps what it picked). They follow the preset.
REQUEST_ONLY = (*MESH_FIELDS, "max_flip", "max_delta_e")
# Fixed order: the scene, then the tier (it sets the defaults of samples, wavelengths, aa),
# then every other field as the request model declares it.
ORDER = ("preset", *REQUEST_ONLY, "quality",
         *(n for n in RenderRequest.model_fields if n not in ("preset", "quality", *REQUEST_ONLY)))
JOB_FIELDS = ORDER[2 + len(REQUEST_ONLY):]
DEFAULT_PRESET = RenderRequest.model_fields["preset"].default


def spell(value: Any) -> str:
    """One spelling per value: shortest round-trip floats, integral floats as integers
    (1, 1.0, 1e0 and 1.00 are the same exposure), tuples comma-separated."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)
    if isinstance(value, list | tuple):
        return ",".join(spell(v) for v in value)
    return str(value)


def canonical_fields(job: Job, preset: Preset, request: RenderRequest | None = None
                     ) -> dict[str, Any]:
    """The fewest fields, in ``ORDER``, that resolve to ``job`` on ``preset``. With a user's
    mesh, ``preset`` is the mesh preset and ``request`` names the preset and the mesh."""
    fields: dict[str, Any] = {}
    name = request.preset if request is not None else preset.name
    if name != DEFAULT_PRESET:
        fields["preset"] = name
    for field in REQUEST_ONLY:
        value = getattr(request, field, None)
        if value is not None:
            fields[field] = tuple(value) if isinstance(value, list) else value
    preset_values = preset_fields(preset)
    if job.quality != preset_values["quality"]:
        fields["quality"] = job.quality
    # As resolve merges them: the tier's settings, unless the preset sets its own.
    base = {**job.tier.render_settings(job.material), **preset_values}
    material = preset_material(preset)
    for field in JOB_FIELDS:
        if field in MATERIAL_FIELDS:
            value, default = getattr(job.material, field), getattr(material, field)
        else:
            value, default = getattr(job, field), base.get(field)
        if _plain(value) != _plain(default):
            # No environment where the preset has one (a user's mesh) is spelled "none".
            fields[field] = NO_ENVIRONMENT if field == "environment" and value is None \
                else _plain(value)
    return fields


def _plain(value: Any) -> Any:
    return tuple(value) if isinstance(value, list) else value


def canonical_query(job: Job, preset: Preset, request: RenderRequest | None = None
                    ) -> dict[str, str]:
    """The canonical query string's fields, spelled, without ``rev``."""
    return {name: spell(value) for name, value in canonical_fields(job, preset, request).items()}


def canonical_url(query: dict[str, str], key: str) -> str:
    """The path and query of a canonical GET URL; ``key`` is its job's cache key."""
    return f"{RENDER_PATH}?{urlencode({**query, 'rev': key}, safe=',')}"
