"""Request parameters: the one place their names, ranges, defaults and docs live.

The ranges are the table of docs/design.md §5; the messages that explain a
rejected value are in ``opaline.model.messages``; the material's own fields are
declared in ``opaline.model.material``. The CLI's ``--help``, the HTTP API's
OpenAPI schema, preset files and material files all read these models, so a
range is written once.
"""

from __future__ import annotations

from types import NoneType, UnionType
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
)
from pydantic_core import PydanticCustomError

from opaline.model import messages
from opaline.model.color_space import ColorSpace

# Re-exported: the material's fields are declared in opaline.model.material.
from opaline.model.material import MATERIAL_FIELDS as MATERIAL_FIELDS
from opaline.model.material import STRICT as STRICT
from opaline.model.material import TWO_PI as TWO_PI
from opaline.model.material import Material as Material
from opaline.model.material import MaterialFields as MaterialFields
from opaline.model.material import MdfName as MdfName

# Re-exported: the CLI and the API read a field's range next to the models.
from opaline.model.messages import field_range as field_range
from opaline.model.scene_fields import SceneFields
from opaline.model.schema_groups import add_groups
from opaline.model.tiers import AntiAliasName, QualityName

ImageFormat = Literal["png", "png16", "npy", "webp", "webp-lossless", "avif", "jpeg"]
# 'auto': the HTTP service picks from the Accept header (anything else draws PNG).
RequestFormat = Literal[ImageFormat, "auto"]
Tonemap = Literal["none", "reinhard", "aces", "neutral"]
# The tiers' own (model/tiers.py): a request names one, or auto.
Quality = QualityName
AntiAlias = AntiAliasName

Pixels = Annotated[int, Field(ge=16, le=2048)]

MIN_WAVELENGTHS = 4  # 1-3 score worse than the RGB model at every sample count (docs/accuracy.md)


def wavelengths_ok(value: int | None) -> int | None:
    if value is not None and value != 0 and not MIN_WAVELENGTHS <= value <= 128:
        raise ValueError("must be 0 (the paper's RGB rotations) or 4 … 128 (1-3 wavelengths"
                         " are less accurate than the RGB model)")
    return value


def wavelengths_schema(schema: dict[str, Any]) -> None:
    """The OpenAPI bounds of ``wavelengths``, read off ``wavelengths_ok`` itself: the
    smallest and largest accepted counts, and every refused count between them under
    ``not``, so the document says exactly what the validator accepts, whatever it is."""
    def ok(n: int) -> bool:
        try:
            wavelengths_ok(n)
        except ValueError:
            return False
        return True

    accepted = [n for n in range(0, 1025) if ok(n)]
    lo, hi = accepted[0], accepted[-1]
    refused = [n for n in range(lo, hi + 1) if not ok(n)]
    schema.update({"minimum": lo, "maximum": hi})
    if refused:
        schema["not"] = {"enum": refused}


class RenderFields(MaterialFields, SceneFields):
    """What a request (or a preset's defaults) may set besides the material."""

    width: Pixels | None = Field(None, description="Image width in pixels, 16 … 2048.")
    height: Pixels | None = Field(None, description="Image height in pixels, 16 … 2048.")
    format: RequestFormat | None = Field(
        None,
        description="'png' (8-bit sRGB), 'png16' (16-bit sRGB), 'npy' (linear float32 RGBA), "
        "'webp' (lossy), 'webp-lossless', 'avif', 'jpeg' (no alpha), or 'auto': "
        "chosen from the Accept header over HTTP (PNG elsewhere).",
    )
    transparent: bool | None = Field(
        None, description="PNG with a transparent background instead of the preset's."
    )
    quality: Quality | None = Field(
        None,
        description="Tier bundling samples, wavelengths and anti-aliasing: draft, standard, high,"
        " reference, or auto (the cheapest measured setting within max_flip / max_delta_e).",
    )
    # quality="auto" (model/auto.py): the cheapest measured setting within these budgets.
    max_flip: Annotated[float, Field(gt=0.0, le=1.0)] | None = Field(
        None, description="With quality 'auto' (or none): largest FLIP against a converged render, "
        "(0, 1]; with a named tier, 422 budget_with_tier."
    )
    max_delta_e: Annotated[float, Field(gt=0.0, le=100.0)] | None = Field(
        None,
        description="With quality 'auto' (or none): largest CIEDE2000 (95th percentile) against a "
        "converged render, (0, 100]; with a named tier, 422 budget_with_tier.",
    )
    samples: Annotated[int, Field(ge=1, le=1024)] | None = Field(
        None, description="Samples per pixel, 1 … 1024 (default: the tier's)."
    )
    # Bounds for UIs live in the schema; the validator gives the exact rule (0 or 4 … 128).
    wavelengths: int | None = Field(
        None,
        json_schema_extra=wavelengths_schema,
        description="0 = the paper's RGB rotations (a film's RGB fast path), else 4 … 128 "
        "wavelengths integrated with CIE 1931 under D65 (default: the tier's; a thin film "
        "takes the tier's film_wavelengths, on a metal its metal_film_wavelengths, a "
        "stack its stack_wavelengths: "
        "GET /v1/tiers).",
    )
    aa: AntiAlias | None = Field(
        None,
        description="'analytic' band-limits the multi-peak cosine by the pixel footprint; 'none' does not (default: the tier's).",
    )
    exposure: Annotated[float, Field(gt=0.0, le=1000.0)] | None = Field(
        None, description="Linear exposure multiplier before tone mapping, (0, 1000]."
    )
    tonemap: Tonemap | None = Field(
        None, description="Tone map before sRGB: 'none' clamps, 'reinhard', 'aces', "
                    "'neutral' (Khronos PBR Neutral: keeps hue)."
    )
    color_space: ColorSpace | None = Field(
        None, description="The image's colour space: 'srgb' (default), or the wider "
        "'display-p3' or 'rec2020', which keep the films' cyans and the stacks' blues that "
        "sRGB cannot show. The file says which (an ICC profile; a PNG also cICP). A colour "
        "outside the space is moved toward the grey of its luminance, hue kept; 'npy' is "
        "linear in the space, a colour outside it with a channel below 0."
    )
    light_azimuth: Annotated[float, Field(ge=-360.0, le=360.0)] | None = Field(
        None,
        description="Moves the key light: azimuth in degrees around the object's up axis, -360 … 360.",
    )
    light_elevation: Annotated[float, Field(ge=-90.0, le=90.0)] | None = Field(
        None, description="Moves the key light: elevation in degrees above the horizon, -90 … 90."
    )

    @field_validator("wavelengths")
    @classmethod
    def _wavelengths_in_range(cls, value: int | None) -> int | None:
        return wavelengths_ok(value)

    @field_validator("max_flip", "max_delta_e")
    @classmethod
    def _budget_needs_auto(cls, value: float | None, info: ValidationInfo) -> float | None:
        # quality is declared (so validated) before the budgets.
        if value is not None and info.data.get("quality") not in (None, "auto"):
            # Its own error type: the public error names it (the schema cannot say that
            # one field excludes another's values).
            raise PydanticCustomError(
                "budget_with_tier", "an error budget chooses the setting: use quality 'auto' "
                "(or leave quality out), not a tier")
        return value


class RenderRequest(RenderFields):
    """A render request: a preset and any fields that override its defaults."""

    model_config = ConfigDict(json_schema_extra=add_groups)
    preset: str = Field("sphere", description="Scene preset name (GET /v1/presets lists them).")


def describe_errors(
    exc: ValidationError | list[dict[str, Any]], model: type[BaseModel] = RenderRequest
) -> list[str]:
    """One line per problem (``opaline.model.messages``), for a request unless told otherwise."""
    return messages.describe_errors(exc, model)


def _is_tuple(annotation: Any) -> bool:
    """Whether a field's type is a tuple, alone or beside None."""
    if get_origin(annotation) in (Union, UnionType):
        return any(_is_tuple(a) for a in get_args(annotation) if a is not NoneType)
    return get_origin(annotation) is tuple


def tuple_fields(model: type[BaseModel]) -> frozenset[str]:
    """The fields that take a tuple (albedo, metal_f0 ...): a query string may repeat them,
    and a query or ``--set`` value of theirs is split at commas."""
    return frozenset(name for name, f in model.model_fields.items() if _is_tuple(f.annotation))
