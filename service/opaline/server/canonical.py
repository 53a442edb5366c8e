"""One URL per image: the canonical GET URL of a render, for shared HTTP caches.

A cache in front of several replicas (nginx, a CDN) keys on the URL, so two
spellings of one request would be rendered twice. The canonical form keeps only
the fields that differ from what the preset (and the quality tier) would give,
in one fixed order, floats in their shortest round-trip spelling, and ends with
``rev``: the image's content key (``Job.cache_key``: request, preset scene,
shader sources, version). A URL carrying the current ``rev`` names one image for
good and is answered ``immutable``. Every answer names it in Content-Location;
any other spelling (or a stale ``rev``) is still answered, with the image, but
cacheable for ``cache_max_age_s`` only, since an upgrade (new shaders, new
preset defaults) changes what it leads to. Not a redirect: clients that do not
follow redirects (httpx, curl without -L) keep working, at the price of a
second render when two replicas see two spellings of one image. MDF plots
(GET /v1/mdf) get the same treatment, their defaults being ``Material()``'s.
"""

from __future__ import annotations

from typing import Any
from urllib.parse import urlencode

from pydantic import Field

from opaline.model.params import MATERIAL_FIELDS, Material, RenderRequest
from opaline.model.presets import Preset
from opaline.model.request import Job, resolve
from opaline.model.scene_fields import MESH_FIELDS
from opaline.server.queries import MdfQuery, RenderQuery

RENDER_PATH = "/v1/render"
MDF_PATH = "/v1/mdf"
# A year: the longest max-age caches honour (RFC 9111 §5.2.2.1 advises at most one).
IMMUTABLE = "public, max-age=31536000, immutable"
# Fixed order: the scene, then the tier (it sets the defaults of samples, wavelengths, aa),
# then every other field as the request model declares it.
# Fields of the request that the Job does not keep: the mesh (part of the scene) and
# quality=auto's error budget (the Job keeps what it picked). They follow the preset.
REQUEST_ONLY = (*MESH_FIELDS, "max_flip", "max_delta_e")
ORDER = ("preset", *REQUEST_ONLY, "quality",
         *(n for n in RenderRequest.model_fields if n not in ("preset", "quality", *REQUEST_ONLY)))


REV = Field(None, pattern="^[0-9a-f]{32}$",
            description="Content key of the image, as the service writes it in the canonical "
                        "URL it names in Content-Location. A URL with the current rev is "
                        "immutable; with none or a stale one the image is still answered.")


class CanonicalQuery(RenderQuery):
    """GET /v1/render's query: the request, and the content key of a canonical URL."""

    rev: str | None = REV

    def request(self) -> RenderRequest:
        return RenderRequest(**self.model_dump(exclude={"rev"}, exclude_none=True))


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


def _field(job: Job, name: str) -> Any:
    value = getattr(job.material, name) if name in MATERIAL_FIELDS else getattr(job, name)
    return tuple(value) if isinstance(value, list) else value


def canonical_fields(job: Job, preset: Preset,
                     request: RenderRequest | None = None) -> dict[str, Any]:
    """The fewest fields, in ``ORDER``, that resolve to ``job`` on ``preset``. With a user's
    mesh, ``preset`` is the mesh preset and ``request`` names the preset and the mesh."""
    fields: dict[str, Any] = {}
    name = request.preset if request is not None else preset.name
    base = resolve(RenderRequest(preset=name), preset)
    if name != RenderRequest.model_fields["preset"].default:
        fields["preset"] = name
    for field in REQUEST_ONLY:
        value = getattr(request, field, None)
        if value is not None:
            fields[field] = tuple(value) if isinstance(value, list) else value
    if job.quality != base.quality:
        fields["quality"] = job.quality
        base = resolve(RenderRequest(preset=name, quality=job.quality), preset)
    for name in ORDER[2 + len(REQUEST_ONLY):]:
        value = _field(job, name)
        if value != _field(base, name):
            fields[name] = value
    return fields


def canonical_job(job: Job, preset: Preset,
                  request: RenderRequest | None = None) -> tuple[Job, dict[str, str]]:
    """``job`` as its canonical query string reads back, and that query (without ``rev``).

    The key must come from the read-back job: spellings that differ only where the
    renderer cannot tell (-0.0 and 0.0) must share one key, one image and one URL."""
    fields = canonical_fields(job, preset, request)
    query = {name: spell(value) for name, value in fields.items()}
    return resolve(CanonicalQuery.model_validate(query).request(), preset), query


def canonical_url(query: dict[str, str], key: str) -> str:
    """The path and query of a canonical GET URL; ``key`` is its job's cache key."""
    return f"{RENDER_PATH}?{urlencode({**query, 'rev': key}, safe=',')}"


def is_canonical(raw_query: str, canonical: str) -> bool:
    """Whether a request's raw query string is exactly the canonical URL's."""
    return canonical.partition("?")[2] == raw_query


class CanonicalMdfQuery(MdfQuery):
    """GET /v1/mdf's query with the content key of a canonical URL."""

    rev: str | None = REV

    def plot(self) -> MdfQuery:
        return MdfQuery(**self.model_dump(exclude={"rev"}, exclude_none=True))


def canonical_plot(params: MdfQuery) -> tuple[MdfQuery, dict[str, str]]:
    """An MDF plot's query without what the defaults give (material fields against
    ``Material()``), spelled once and read back, as ``canonical_job`` does for renders."""
    material, default = Material(**params.model_dump(include=set(MATERIAL_FIELDS),
                                                     exclude_none=True)), Material()
    query = {name: spell(getattr(material, name)) for name in MATERIAL_FIELDS
             if getattr(material, name) != getattr(default, name)}
    query.update({name: spell(getattr(params, name)) for name in ("size", "format", "wavelengths")
                  if getattr(params, name) != MdfQuery.model_fields[name].default})
    return CanonicalMdfQuery.model_validate(query).plot(), query


def mdf_url(query: dict[str, str], key: str) -> str:
    return f"{MDF_PATH}?{urlencode({**query, 'rev': key}, safe=',')}"
