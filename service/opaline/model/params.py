"""Request parameters: the one place their names, ranges, defaults and docs live.

DESIGN.md §3. The CLI's ``--help``, the HTTP API's OpenAPI schema, preset
files and material files all read these models, so a range is written once.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
)

TWO_PI = 2.0 * math.pi

MdfName = Literal["ashikhmin", "multipeak"]
ImageFormat = Literal["png", "png16", "npy"]
Tonemap = Literal["none", "reinhard", "aces"]
Quality = Literal["draft", "standard", "high", "reference", "auto"]
AntiAlias = Literal["none", "analytic"]

Exponent = Annotated[float, Field(ge=0.0, le=1e6)]
Frequency = Annotated[float, Field(ge=0.0, le=1000.0)]
Anisotropy = Annotated[float, Field(ge=0.0, le=1000.0)]
Angle = Annotated[float, Field(ge=-TWO_PI, le=TWO_PI)]
Weight = Annotated[float, Field(ge=0.0, le=100.0)]
Unit = Annotated[float, Field(ge=0.0, le=1.0)]
Pixels = Annotated[int, Field(ge=16, le=2048)]

STRICT = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


MIN_WAVELENGTHS = 4  # 1-3 score worse than the RGB model at every sample count (docs/accuracy.md)


def wavelengths_ok(value: int | None) -> int | None:
    if value is not None and value != 0 and not MIN_WAVELENGTHS <= value <= 128:
        raise ValueError("must be 0 (the paper's RGB rotations) or 4 … 128 (1-3 wavelengths"
                         " are less accurate than the RGB model)")
    return value


class MaterialFields(BaseModel):
    """Material parameters; ``None`` means "take the preset's value"."""

    model_config = STRICT

    mdf: MdfName | None = Field(
        None, description="Microfacet distribution: 'ashikhmin' (eq. 1) or 'multipeak' (eqs. 3-4)."
    )
    ex: Exponent | None = Field(
        None, description="Ashikhmin-Shirley exponent along the tangent (eq. 1), 0 … 1e6."
    )
    ey: Exponent | None = Field(
        None, description="Ashikhmin-Shirley exponent along the bitangent (eq. 1), 0 … 1e6."
    )
    mu_f: Frequency | None = Field(
        None, description="Multi-peak frequency: rings across the MDF disc (eq. 4), 0 … 1000."
    )
    alpha: Anisotropy | None = Field(
        None, description="Multi-peak anisotropy along the tangent (eq. 4), 0 … 1000."
    )
    beta: Anisotropy | None = Field(
        None, description="Multi-peak anisotropy along the bitangent (eq. 4), 0 … 1000."
    )
    theta1: Angle | None = Field(
        None, description="Rotation of the green channel's MDF in radians (eq. 2), -2π … 2π."
    )
    theta2: Angle | None = Field(
        None, description="Rotation of the blue channel's MDF in radians (eq. 2), -2π … 2π."
    )
    kd: Weight | None = Field(None, description="Diffuse weight, 0 … 100.")
    ks: Weight | None = Field(None, description="Specular weight, 0 … 100.")
    albedo: tuple[Unit, Unit, Unit] | None = Field(
        None, description="Diffuse colour, linear RGB, each 0 … 1."
    )
    f0: Unit | None = Field(
        None, description="Schlick reflectance at normal incidence, 0 … 1 (1 turns Fresnel off)."
    )


class RenderFields(MaterialFields):
    """What a request (or a preset's defaults) may set besides the material."""

    width: Pixels | None = Field(None, description="Image width in pixels, 16 … 2048.")
    height: Pixels | None = Field(None, description="Image height in pixels, 16 … 2048.")
    format: ImageFormat | None = Field(
        None,
        description="'png' (8-bit sRGB), 'png16' (16-bit sRGB) or 'npy' (linear float32 RGBA).",
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
        None, description="With quality 'auto': largest FLIP against a converged render, (0, 1]."
    )
    max_delta_e: Annotated[float, Field(gt=0.0, le=100.0)] | None = Field(
        None,
        description="With quality 'auto': largest CIEDE2000 (95th percentile) against a converged render, (0, 100].",
    )
    samples: Annotated[int, Field(ge=1, le=1024)] | None = Field(
        None, description="Samples per pixel, 1 … 1024 (default: the tier's)."
    )
    # Bounds for UIs live in the schema; the validator gives the exact rule (0 or 4 … 128).
    wavelengths: int | None = Field(
        None,
        json_schema_extra={"minimum": 0, "maximum": 128},
        description="0 = the paper's RGB rotations, else 4 … 128 wavelengths integrated with CIE 1931 (default: the tier's).",
    )
    aa: AntiAlias | None = Field(
        None,
        description="'analytic' band-limits the multi-peak cosine by the pixel footprint; 'none' does not (default: the tier's).",
    )
    exposure: Annotated[float, Field(gt=0.0, le=1000.0)] | None = Field(
        None, description="Linear exposure multiplier before tone mapping, (0, 1000]."
    )
    tonemap: Tonemap | None = Field(
        None, description="Tone map before sRGB: 'none' clamps, 'reinhard', 'aces'."
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
            raise ValueError("an error budget chooses the setting: use quality 'auto' (or leave"
                             " quality out), not a tier")
        return value


class RenderRequest(RenderFields):
    """A render request: a preset and any fields that override its defaults."""

    preset: str = Field("sphere", description="Scene preset name (GET /v1/presets lists them).")


class Material(BaseModel):
    """A fully specified material, as the renderer consumes it."""

    model_config = STRICT

    mdf: MdfName = "multipeak"
    ex: Exponent = 100.0
    ey: Exponent = 10.0
    mu_f: Frequency = 8.5
    alpha: Anisotropy = 2.0
    beta: Anisotropy = 1.2
    theta1: Angle = 0.1
    theta2: Angle = 0.2
    kd: Weight = 0.0
    ks: Weight = 1.0
    albedo: tuple[Unit, Unit, Unit] = (0.5, 0.5, 0.5)
    f0: Unit = 1.0


MATERIAL_FIELDS = tuple(Material.model_fields)


def field_range(model: type[BaseModel], name: str) -> str | None:
    """The allowed range of a numeric field, as 'lo … hi', read from its constraints."""
    info = model.model_fields.get(name)
    if info is None:
        return None
    lo = hi = None
    lo_open = hi_open = False
    for meta in _constraints(info):
        lo = getattr(meta, "ge", lo)
        hi = getattr(meta, "le", hi)
        if getattr(meta, "gt", None) is not None:
            lo, lo_open = meta.gt, True
        if getattr(meta, "lt", None) is not None:
            hi, hi_open = meta.lt, True
    if lo is None and hi is None:
        return None
    return f"{'(' if lo_open else '['}{_fmt(lo)} … {_fmt(hi)}{')' if hi_open else ']'}"


def _constraints(info) -> list[Any]:
    found = list(info.metadata)
    annotation = info.annotation
    for arg in getattr(annotation, "__args__", ()) or ():
        found.extend(getattr(arg, "__metadata__", ()))
        for inner in getattr(arg, "__args__", ()) or ():
            found.extend(getattr(inner, "__metadata__", ()))
    return [meta for item in found for meta in getattr(item, "metadata", [item])]


def _fmt(value: float | None) -> str:
    if value is None:
        return "∞"
    if isinstance(value, float) and abs(abs(value) - TWO_PI) < 1e-12:
        return "-2π" if value < 0 else "2π"
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e7:
        return str(int(value)) if abs(value) < 1e5 else f"{value:g}"
    return f"{value:g}"


RANGE_ERRORS = {"less_than_equal", "greater_than_equal", "less_than", "greater_than"}


def _shown(value: Any) -> str:
    """A number as typed: query strings and CLI flags give numbers as text."""
    return value if isinstance(value, str) else repr(value)


def _tuple_length(model: type[BaseModel], name: str) -> int:
    info = model.model_fields.get(name)
    for arg in getattr(info.annotation, "__args__", ()) if info else ():
        if getattr(arg, "__origin__", None) is tuple:
            return len(arg.__args__)
    return 0


def _nested_model(annotation: Any) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()) or ():
        found = _nested_model(arg)
        if found is not None:
            return found
    return None


def _owner(model: type[BaseModel], loc: tuple) -> tuple[type[BaseModel], str]:
    """The (possibly nested) model that owns the last named field of an error location."""
    owner, name = model, "request"
    current: type[BaseModel] | None = model
    for part in loc:
        if isinstance(part, int) or current is None:
            continue
        owner, name = current, str(part)
        info = current.model_fields.get(name)
        current = _nested_model(info.annotation) if info is not None else None
    return owner, name


def describe_errors(
    exc: ValidationError | list[dict[str, Any]], model: type[BaseModel] = RenderRequest
) -> list[str]:
    """One line per problem: the field, the value given, and what is allowed.

    Takes a ValidationError or its ``errors()`` list (FastAPI hands over the list)."""
    lines = []
    for err in exc.errors() if isinstance(exc, ValidationError) else exc:
        loc = [str(p) for p in err["loc"] if not isinstance(p, int) or len(err["loc"]) > 1]
        owner, name = _owner(model, tuple(err["loc"]))
        where = ".".join(loc) or name
        given = err.get("input")
        allowed = field_range(owner, name)
        kind = err["type"]
        if kind == "extra_forbidden":
            known = ", ".join(sorted(owner.model_fields))
            lines.append(f"{where}: unknown field (known fields: {known})")
        elif kind == "missing" and isinstance(err["loc"][-1], int):
            lines.append(f"{name}: expected {_tuple_length(owner, name)} values, got fewer")
        elif kind == "missing":
            lines.append(f"{where}: required field missing")
        elif kind in RANGE_ERRORS and allowed:
            lines.append(f"{where}={_shown(given)} is out of range: allowed {allowed}")
        elif kind == "finite_number":
            lines.append(
                f"{where}={_shown(given)} must be a finite number"
                + (f" in {allowed}" if allowed else "")
            )
        else:
            msg = err["msg"].removeprefix("Value error, ")
            text = f"{where}={given!r}: {msg}"
            if allowed and kind != "literal_error":
                text += f" (allowed {allowed})"
            lines.append(text)
    return lines
