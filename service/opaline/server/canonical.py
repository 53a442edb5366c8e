"""One URL per image: the canonical GET URLs' query models, for shared HTTP caches.

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

from urllib.parse import urlencode

from pydantic import Field

from opaline.model.material import MDF_PLOT_FIELDS
from opaline.model.params import Material, RenderRequest
from opaline.pipeline.canonical import spell
from opaline.server.queries import MdfQuery, RenderQuery

MDF_PATH = "/v1/mdf"
# A year: the longest max-age caches honour (RFC 9111 §5.2.2.1 advises at most one).
IMMUTABLE = "public, max-age=31536000, immutable"

REV = Field(None, pattern="^[0-9a-f]{32}$",
            description="Content key of the image, as the service writes it in the canonical "
                        "URL it names in Content-Location. A URL with the current rev is "
                        "immutable; with none or a stale one the image is still answered.")


class CanonicalQuery(RenderQuery):
    """GET /v1/render's query: the request, and the content key of a canonical URL."""

    rev: str | None = REV

    def request(self) -> RenderRequest:
        return RenderRequest(**self.model_dump(exclude={"rev"}, exclude_none=True))


def is_canonical(raw_query: str, canonical: str) -> bool:
    """Whether a request's raw query string is exactly the canonical URL's."""
    return canonical.partition("?")[2] == raw_query


class CanonicalMdfQuery(MdfQuery):
    """GET /v1/mdf's query with the content key of a canonical URL."""

    rev: str | None = REV

    def plot(self) -> MdfQuery:
        return MdfQuery(**self.model_dump(exclude={"rev"}, exclude_none=True))


def plot_material(params: MdfQuery) -> Material:
    """The plot's material: its MDF fields, every other field at its default (a field the
    plot does not read must not give one image a second URL and key)."""
    return Material(**params.model_dump(include=set(MDF_PLOT_FIELDS), exclude_none=True))


def canonical_plot(params: MdfQuery) -> tuple[MdfQuery, dict[str, str]]:
    """An MDF plot's query without what the defaults give (material fields against
    ``Material()``), spelled once and read back, as ``canonical_job`` does for renders."""
    material, default = plot_material(params), Material()
    query = {name: spell(getattr(material, name)) for name in MDF_PLOT_FIELDS
             if getattr(material, name) != getattr(default, name)}
    query.update({name: spell(getattr(params, name)) for name in ("size", "format", "wavelengths")
                  if getattr(params, name) != MdfQuery.model_fields[name].default})
    return CanonicalMdfQuery.model_validate(query).plot(), query


def mdf_url(query: dict[str, str], key: str) -> str:
    return f"{MDF_PATH}?{urlencode({**query, 'rev': key}, safe=',')}"
