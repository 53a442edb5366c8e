"""The query-string forms of the request models: GET /v1/render and GET /v1/mdf.

A query string has no arrays, so a tuple field is written comma-separated
(``albedo=R,G,B``, ``tangent_axis=X,Y,Z``) or as the parameter repeated, one value
each time; every other field is the request model's own.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal, TypeVar

from pydantic import BaseModel, Field, field_validator
from pydantic_core import from_json
from starlette.requests import Request

from opaline.errors import PublicError
from opaline.model.material import Unit
from opaline.model.messages import UNKNOWN_NAMED, shown_name
from opaline.model.params import (
    MaterialFields,
    Pixels,
    RenderRequest,
    tuple_fields,
    wavelengths_ok,
    wavelengths_schema,
)
from opaline.model.strict_json import refuse_duplicate_keys, validate_strictly


def _comma_list(value: Any) -> Any:
    """``albedo=0.1,0.2,0.3`` (or the parameter repeated three times) → three values."""
    if isinstance(value, list) and len(value) == 1 and isinstance(value[0], str):
        value = value[0]
    return value.split(",") if isinstance(value, str) else value


class RenderQuery(RenderRequest):
    """A render request in a query string."""

    albedo: tuple[Unit, Unit, Unit] | None = Field(
        None, description="Diffuse colour, linear RGB, each 0 … 1, written R,G,B.")

    _tuples = field_validator(*tuple_fields(RenderRequest) | {"albedo"},
                              mode="before")(_comma_list)


class MdfQuery(MaterialFields):
    """An MDF plot: the material, the plot size and format, the wavelength count."""

    albedo: tuple[Unit, Unit, Unit] | None = Field(
        None, description="Diffuse colour (unused by the plot), linear RGB, each 0 … 1, R,G,B.")
    size: Pixels = Field(256, description="Plot size N (an N×N image), 16 … 2048.")
    format: Literal["png", "npy"] = Field(
        "png", description="'png' (normalised by the maximum, sRGB) or 'npy' (linear D, float32).")
    # As RenderFields.wavelengths: bounds for the schema, the exact rule in the validator.
    wavelengths: int = Field(
        0, json_schema_extra=wavelengths_schema,
        description="0 = the paper's RGB rotations, else 4 … 128 wavelengths (CIE 1931).")

    _tuples = field_validator(*tuple_fields(MaterialFields) | {"albedo"},
                              mode="before")(_comma_list)
    _wavelengths = field_validator("wavelengths")(wavelengths_ok)


class Malformed(PublicError, ValueError):
    """A body that is not a JSON document: not UTF-8, not JSON, or nested too deep (400)."""

    status, reason = 400, "malformed"


class QueryOnPost(PublicError, ValueError):
    """A POST with a query string: its fields are read from the body only, and a field
    sent in the query (``POST /v1/render?mu_f=2000``) was silently not used (422)."""

    status, reason = 422, "invalid"


class NotJson(PublicError, ValueError):
    """A body sent as something other than JSON (415): ``curl -d`` labels it a form, and
    a form's fields are not what the service would read from it."""

    status, reason = 415, "unsupported_media_type"


def require_json(content_type: str | None) -> None:
    """``NotJson`` unless the body is labelled ``application/json`` (or a ``+json`` type,
    parameters such as ``charset`` allowed) or not labelled at all, as FastAPI reads a
    body."""
    if content_type is None:
        return
    media = content_type.split(";", 1)[0].strip().lower()
    if media == "application/json" or (media.startswith("application/")
                                       and media.endswith("+json")):
        return
    raise NotJson(f"content-type: the body must be JSON, sent as 'application/json' (it was "
                  f"{shown_name(content_type)!r}; curl: -H 'content-type: application/json')")


def refuse_query(query: Mapping[str, str]) -> None:
    """``QueryOnPost`` naming the query's parameters (as many as an unknown field's
    message names, the rest counted), if it has any."""
    names = list(dict.fromkeys(query))
    if names:
        more = len(names) - UNKNOWN_NAMED
        shown = ", ".join(names[:UNKNOWN_NAMED]) + (f" and {more} more" if more > 0 else "")
        raise QueryOnPost(f"query: a POST reads its fields from the JSON body, not the query "
                          f"string ({shown}): send them in the body")


async def json_body(request: Request) -> bytes:
    """A POST's JSON body, its query string and content type checked first."""
    refuse_query(request.query_params)
    require_json(request.headers.get("content-type"))
    return await request.body()


Model = TypeVar("Model", bound=BaseModel)


def parse_body(raw: bytes, model: type[Model]) -> Model:
    """A JSON body as ``model``, strictly: numbers must be JSON numbers and booleans JSON
    booleans, as the OpenAPI document says ({"mu_f": "6"} and {"mu_f": false} are refused),
    and a key given twice in one object is refused (``DuplicateKey``);
    an integer field takes an integral number written as a float (178.0), as JSON Schema's
    "integer" does. pydantic's parser bounds the nesting depth; a parse failure is
    ``Malformed``."""
    if not raw.strip():
        raise Malformed("body: a JSON object is required ({} renders the defaults)")
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise Malformed(f"body: not valid UTF-8 (byte {exc.start})") from None
    try:
        data = from_json(raw)
    except ValueError as exc:
        raise Malformed(f"body: not valid JSON ({exc})") from None
    # Parsed again only to see every key (pydantic's parser keeps the last of a repeated
    # one); its nesting is already bounded by the parse above.
    refuse_duplicate_keys(raw, "the JSON body")
    return validate_strictly(data, model)
