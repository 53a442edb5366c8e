"""Request parameters (opaline.model.params): docs/design.md §5's ranges, enforced and explained."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from pydantic import ValidationError

from opaline.model.params import Material, RenderRequest, describe_errors

TAU = 2 * math.pi
# docs/design.md §5 (plus exposure and the light angles), written out independently.
FLOATS = {
    "ex": (0.0, 1e6), "ey": (0.0, 1e6),
    "mu_f": (0.0, 1000.0), "alpha": (0.0, 1000.0), "beta": (0.0, 1000.0),
    "theta1": (-TAU, TAU), "theta2": (-TAU, TAU),
    "kd": (0.0, 100.0), "ks": (0.0, 100.0),
    "f0": (0.0, 1.0),
    "light_azimuth": (-360.0, 360.0), "light_elevation": (-90.0, 90.0),
}
INTS = {"width": (16, 2048), "height": (16, 2048), "samples": (1, 1024)}
MATERIAL_FLOATS = [name for name in FLOATS if name in Material.model_fields]
NOT_FINITE = [math.nan, math.inf, -math.inf, "nan", "inf"]
RANGE = re.compile(r"([\[(])(\S+) … (\S+)([\])])")


def errors(**fields) -> list[str]:
    with pytest.raises(ValidationError) as info:
        RenderRequest(**fields)
    return describe_errors(info.value)


def parse_bound(text: str) -> float:
    """A bound as printed: '1000', '1e+06', '-2π', '2π'."""
    text = text.replace("−", "-")
    if text.endswith("π"):
        coefficient = text[:-1]
        sign = {"": 1.0, "-": -1.0}.get(coefficient)
        return (sign if sign is not None else float(coefficient)) * math.pi
    return float(text)


def stated_range(line: str) -> tuple[str, float, float, str]:
    match = RANGE.search(line)
    assert match, f"no range in {line!r}"
    return match.group(1), parse_bound(match.group(2)), parse_bound(match.group(3)), match.group(4)


@pytest.mark.parametrize("name", sorted(FLOATS))
def test_float_field_accepts_its_ends(name):
    """Both ends of each float range are accepted unchanged (no clamping)."""
    lo, hi = FLOATS[name]
    assert getattr(RenderRequest(**{name: lo}), name) == lo
    assert getattr(RenderRequest(**{name: hi}), name) == hi


@pytest.mark.parametrize("name", sorted(FLOATS))
def test_float_field_rejects_just_outside(name):
    """The next float beyond either end is rejected."""
    lo, hi = FLOATS[name]
    for value in (np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf)):
        with pytest.raises(ValidationError):
            RenderRequest(**{name: float(value)})


@pytest.mark.parametrize("value", NOT_FINITE, ids=repr)
@pytest.mark.parametrize("name", sorted(FLOATS) + sorted(INTS) + ["exposure"])
def test_numeric_field_rejects_non_finite(name, value):
    """NaN and ±inf (also as strings) are rejected for every numeric field."""
    with pytest.raises(ValidationError):
        RenderRequest(**{name: value})


@pytest.mark.parametrize("name", MATERIAL_FLOATS)
def test_material_model_enforces_the_same_ranges(name):
    """The fully specified Material refuses what the request refuses, and takes the ends."""
    lo, hi = FLOATS[name]
    Material(**{name: lo})
    Material(**{name: hi})
    for value in (float(np.nextafter(lo, -np.inf)), float(np.nextafter(hi, np.inf)), math.nan):
        with pytest.raises(ValidationError):
            Material(**{name: value})


@pytest.mark.parametrize("name", sorted(INTS))
def test_int_field_range(name):
    """Integer fields take their ends and refuse one beyond and fractions."""
    lo, hi = INTS[name]
    assert getattr(RenderRequest(**{name: lo}), name) == lo
    assert getattr(RenderRequest(**{name: hi}), name) == hi
    for value in (lo - 1, hi + 1, lo + 0.5):
        with pytest.raises(ValidationError):
            RenderRequest(**{name: value})


def test_exposure_is_open_at_zero():
    """exposure takes (0, 1000]: 0 is refused, the smallest positive float and 1000 are not."""
    RenderRequest(exposure=5e-324)
    RenderRequest(exposure=1000.0)
    for value in (0.0, -1.0, float(np.nextafter(1000.0, np.inf))):
        with pytest.raises(ValidationError):
            RenderRequest(exposure=value)


@pytest.mark.parametrize("index", [0, 1, 2])
def test_albedo_components(index):
    """Each albedo component takes 0 and 1 and refuses just outside and NaN."""
    for ok in (0.0, 1.0):
        rgb = [0.5, 0.5, 0.5]
        rgb[index] = ok
        assert RenderRequest(albedo=tuple(rgb)).albedo[index] == ok
    for bad in (float(np.nextafter(0.0, -1.0)), float(np.nextafter(1.0, 2.0)), math.nan, math.inf):
        rgb = [0.5, 0.5, 0.5]
        rgb[index] = bad
        with pytest.raises(ValidationError):
            RenderRequest(albedo=tuple(rgb))
    with pytest.raises(ValidationError):
        RenderRequest(albedo=(0.5, 0.5))


@pytest.mark.parametrize("value", [0, 4, 5, 64, 127, 128])
def test_wavelengths_accepted(value):
    """wavelengths takes 0 (the paper's RGB) and 4 … 128."""
    assert RenderRequest(wavelengths=value).wavelengths == value


@pytest.mark.parametrize("value", [1, 2, 3, 129, -1, 1000])
def test_wavelengths_refused(value):
    """wavelengths refuses 1-3 (less accurate than RGB), 129 and the like, naming the field
    and what is allowed."""
    (line,) = errors(wavelengths=value)
    assert f"wavelengths={value}" in line
    assert "4 … 128" in line and "0" in line


def test_describe_errors_example():
    """mu_f=2000 is described as 'mu_f=2000 … [0 … 1000]'."""
    (line,) = errors(mu_f=2000)
    assert "mu_f=2000" in line
    assert "[0 … 1000]" in line


@pytest.mark.parametrize("name", sorted(FLOATS))
def test_describe_errors_names_field_value_and_range(name):
    """An out-of-range line names the field, the value given, and the exact allowed range."""
    lo, hi = FLOATS[name]
    given = hi * 2 if hi > 0 else hi + 1
    (line,) = errors(**{name: given})
    assert line.startswith(f"{name}=")
    assert repr(given) in line or f"{given:g}" in line
    open_, got_lo, got_hi, close = stated_range(line)
    assert (open_, close) == ("[", "]")
    assert got_lo == pytest.approx(lo, rel=1e-12) and got_hi == pytest.approx(hi, rel=1e-12)


@pytest.mark.parametrize("name", sorted(INTS))
def test_describe_errors_for_int_fields(name):
    """Integer fields state their range too."""
    lo, hi = INTS[name]
    (line,) = errors(**{name: hi + 1})
    assert f"{name}={hi + 1}" in line
    assert stated_range(line)[1:3] == (lo, hi)


def test_describe_errors_marks_open_ends():
    """exposure's range is shown open at 0: '(0 … 1000]'."""
    (line,) = errors(exposure=0)
    assert stated_range(line) == ("(", 0.0, 1000.0, "]")


@pytest.mark.parametrize("value", [math.nan, math.inf])
def test_describe_errors_for_non_finite(value):
    """A NaN or inf line names the field, says it must be finite, and gives the range."""
    (line,) = errors(mu_f=value)
    assert line.startswith("mu_f=")
    assert "finite" in line
    assert stated_range(line)[1:3] == (0.0, 1000.0)


def test_describe_errors_albedo_component():
    """An albedo component out of range is named with its index."""
    (line,) = errors(albedo=(0.2, 1.5, 0.1))
    assert line.startswith("albedo.1=1.5")
    assert stated_range(line)[1:3] == (0.0, 1.0)


def test_one_line_per_problem():
    """Each invalid field gives its own line."""
    lines = errors(mu_f=-1, ex=2e6, width=8)
    assert len(lines) == 3
    for name in ("mu_f", "ex", "width"):
        assert sum(line.startswith(f"{name}=") for line in lines) == 1


def test_unknown_fields_refused_and_listed():
    """Unknown fields are each refused by name, with the known fields listed."""
    lines = errors(zoom=3, colour="red", mu_f=1.0)
    assert len(lines) == 2
    assert any(line.startswith("zoom") and "unknown" in line for line in lines)
    assert any(line.startswith("colour") and "unknown" in line for line in lines)
    for name in ("mu_f", "theta1", "width", "wavelengths"):
        assert name in lines[0]


def test_many_unknown_fields_make_a_short_answer():
    """A request may carry any number of unknown fields: five are named, the rest counted,
    the known fields listed once (each line listed them all: 12,000 made 19 MB)."""
    lines = errors(**{f"x{i}": 1 for i in range(5000)})
    assert len(lines) == 6 and lines[-1] == "… and 4995 more unknown fields"
    assert sum("(known fields:" in line for line in lines) == 1
    assert sum(map(len, lines)) < 4000


@pytest.mark.parametrize(("field", "value", "choices"), [
    ("mdf", "beckmann", ("ashikhmin", "multipeak")),
    ("format", "gif", ("png", "png16", "npy")),
    ("tonemap", "filmic", ("none", "reinhard", "aces", "neutral")),
    ("quality", "ultra", ("draft", "standard", "high", "reference")),
    ("aa", "msaa", ("none", "analytic")),
])
def test_choice_fields(field, value, choices):
    """Choice fields accept their choices and refuse others, listing the choices."""
    for choice in choices:
        assert getattr(RenderRequest(**{field: choice}), field) == choice
    (line,) = errors(**{field: value})
    assert line.startswith(f"{field}=")
    for choice in choices:
        assert choice in line


def test_models_are_frozen():
    """Parsed requests cannot be mutated after validation."""
    request = RenderRequest(mu_f=2.0)
    with pytest.raises(ValidationError):
        request.mu_f = 2000.0


@pytest.mark.parametrize(("given", "kept"), [
    ((0.0, 2.0, 0.0), None), ((0.0, 1.0, 0.0), None), ((0.0, 0.0, 0.0), None),
    ((3.0, 0.0, 4.0), (0.6, 0.0, 0.8)), ((0.0, 0.0, -5.0), (0.0, 0.0, -1.0))])
def test_a_tangent_axis_is_kept_as_its_direction(given, kept):
    """Only the axis's direction draws: 0,2,0 rendered the default's image under a key and
    a canonical URL of its own, and an explicit 0,1,0 was kept in the URL."""
    assert RenderRequest(tangent_axis=given).tangent_axis == kept
