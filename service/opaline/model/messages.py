"""How a validation problem reads: the field, the value given, and what is allowed.

Works on any pydantic model (requests, presets, settings): the allowed range is
read from the field's own constraints, so it is written once, in the model.
"""

from __future__ import annotations

import difflib
import math
from typing import Any

from pydantic import BaseModel, ValidationError
from pydantic.fields import FieldInfo

TWO_PI = 2.0 * math.pi
# Unknown fields named one by one (with a "did you mean"); the rest are counted. Each was
# a line listing every known field: 12,000 in a 97 KB query made a 19 MB answer.
UNKNOWN_NAMED = 5


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


def _constraints(info: FieldInfo) -> list[Any]:
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


def _owner(model: type[BaseModel], loc: tuple[int | str, ...]) -> tuple[type[BaseModel], str]:
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


NAME_SHOWN = 64  # an unknown name longer than any field's is cut to this in a message


def shown_name(name: str) -> str:
    """An unknown field's name as a message echoes it: a 100 KB name was echoed whole in
    each of the answer's lines and fields (a 301 KB body)."""
    return name if len(name) <= NAME_SHOWN else name[:NAME_SHOWN - 1] + "…"


def describe_errors(exc: ValidationError | list[dict[str, Any]], model: type[BaseModel]) -> list[str]:
    """One line per problem: the field, the value given, and what is allowed.

    Takes a ValidationError or its ``errors()`` list (FastAPI hands over the list)."""
    lines: list[str] = []
    unknown = 0  # a request may carry any number: name a few, list the known fields once
    for err in exc.errors() if isinstance(exc, ValidationError) else exc:
        loc = [str(p) for p in err["loc"] if not isinstance(p, int) or len(err["loc"]) > 1]
        owner, name = _owner(model, tuple(err["loc"]))
        where = ".".join(loc) or name
        given = err.get("input")
        allowed = field_range(owner, name)
        kind = err["type"]
        if kind == "extra_forbidden":
            unknown += 1
            if unknown > UNKNOWN_NAMED:
                continue
            known = sorted(owner.model_fields)
            near = difflib.get_close_matches(name, known, n=1)  # "muf" → mu_f
            hint = f", did you mean {near[0]}?" if near else ""
            listed = f" (known fields: {', '.join(known)})" if unknown == 1 else ""
            lines.append(f"{shown_name(where)}: unknown field{hint}{listed}")
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
    if unknown > UNKNOWN_NAMED:
        lines.append(f"… and {unknown - UNKNOWN_NAMED} more unknown fields")
    return lines
