"""The query-string forms of the request models: GET /v1/render and GET /v1/mdf.

A query string has no arrays, so a colour is written ``albedo=R,G,B`` (or the
parameter repeated three times); every other field is the request model's own.
"""

from __future__ import annotations

from typing import Any, Literal, TypeVar

from pydantic import BaseModel, Field, ValidationError, field_validator

from opaline.model.params import (
    MaterialFields,
    Pixels,
    RenderRequest,
    Unit,
    wavelengths_ok,
    wavelengths_schema,
)


def _comma_list(value: Any) -> Any:
    """``albedo=0.1,0.2,0.3`` (or the parameter repeated three times) → three values."""
    if isinstance(value, list) and len(value) == 1 and isinstance(value[0], str):
        value = value[0]
    return value.split(",") if isinstance(value, str) else value


class RenderQuery(RenderRequest):
    """A render request in a query string."""

    albedo: tuple[Unit, Unit, Unit] | None = Field(
        None, description="Diffuse colour, linear RGB, each 0 … 1, written R,G,B.")

    _albedo = field_validator("albedo", mode="before")(_comma_list)


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
        description="0 = the paper's RGB rotations, else 3 … 128 wavelengths (CIE 1931).")

    _albedo = field_validator("albedo", mode="before")(_comma_list)
    _wavelengths = field_validator("wavelengths")(wavelengths_ok)


class Malformed(ValueError):
    """A body that is not a JSON document: not UTF-8, not JSON, or nested too deep (400)."""


Model = TypeVar("Model", bound=BaseModel)


def parse_body(raw: bytes, model: type[Model]) -> Model:
    """A JSON body as ``model``, strictly: numbers must be JSON numbers and booleans JSON
    booleans, as the OpenAPI document says ({"mu_f": "6"} and {"mu_f": false} are refused).
    pydantic's parser bounds the nesting depth; a parse failure is ``Malformed``."""
    if not raw.strip():
        raise Malformed("body: a JSON object is required ({} renders the defaults)")
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise Malformed(f"body: not valid UTF-8 (byte {exc.start})") from None
    try:
        return model.model_validate_json(raw, strict=True)
    except ValidationError as exc:
        broken = [e for e in exc.errors() if e["type"] == "json_invalid"]
        if broken:
            reason = (broken[0].get("ctx") or {}).get("error", "")
            raise Malformed(f"body: not valid JSON ({reason})" if reason
                            else "body: not valid JSON") from None
        raise
