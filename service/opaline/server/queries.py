"""The query-string forms of the request models: GET /v1/render and GET /v1/mdf.

A query string has no arrays, so a colour is written ``albedo=R,G,B`` (or the
parameter repeated three times); every other field is the request model's own.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, field_validator

from opaline.model.params import MaterialFields, Pixels, RenderRequest, Unit, wavelengths_ok


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
        0, json_schema_extra={"minimum": 0, "maximum": 128},
        description="0 = the paper's RGB rotations, else 4 … 128 wavelengths (CIE 1931).")

    _albedo = field_validator("albedo", mode="before")(_comma_list)
    _wavelengths = field_validator("wavelengths")(wavelengths_ok)
