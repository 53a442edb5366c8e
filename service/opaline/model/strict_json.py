"""JSON read as the OpenAPI document types it, for a request body and a material file
alike: numbers must be JSON numbers and booleans JSON booleans ({"mu_f": "6"} and
{"mu_f": false} are refused), a key given twice in one object is refused, and an integer
field takes an integral number written as a float (178.0), as JSON Schema's "integer"
does."""

from __future__ import annotations

import json
from functools import cache
from typing import Any, TypeVar

from pydantic import BaseModel
from pydantic_core import to_json

from opaline.errors import PublicError
from opaline.model.messages import shown_name

Model = TypeVar("Model", bound=BaseModel)


class DuplicateKey(PublicError, ValueError):
    """A key named twice in one object: JSON leaves which one counts to the parser (RFC
    8259 §4), and the last silently won (422)."""

    status, reason = 422, "invalid"

    def __init__(self, message: str, field: str) -> None:
        super().__init__(message)
        self.field = field

    def field_problems(self) -> list[dict[str, str]]:
        return [{"field": self.field, "message": str(self)}]


def refuse_duplicate_keys(text: str | bytes, where: str) -> None:
    """``DuplicateKey`` if an object of the JSON ``text`` names a key twice; ``where``
    names the text in the message ("the JSON body", a file's name)."""
    def unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        found: dict[str, Any] = {}
        for key, value in pairs:
            if key in found:
                name = key if key.isidentifier() else json.dumps(key)[:80]
                raise DuplicateKey(f"{name}: given more than once in one object of {where} "
                                   "(which one counts is the parser's choice): give it once",
                                   shown_name(key))
            found[key] = value
        return found

    json.loads(text, object_pairs_hook=unique)


def _plain(value: Any) -> Any:
    """A NumPy scalar or array as its Python number or list (``opaline.render`` is given
    them); anything else as its text, which no number or boolean field takes."""
    tolist = getattr(value, "tolist", None)
    return tolist() if callable(tolist) else str(value)


def validate_strictly(data: Any, model: type[Model]) -> Model:
    """``data`` (parsed JSON or TOML, or a caller's dict) as ``model``, in pydantic's strict
    JSON mode."""
    if isinstance(data, dict):
        for name in integer_fields(model) & data.keys():
            value = data[name]
            if isinstance(value, float) and value.is_integer():
                data[name] = int(value)
    text = to_json(data, inf_nan_mode="constants", fallback=_plain)
    return model.model_validate_json(text, strict=True)


@cache
def integer_fields(model: type[BaseModel]) -> frozenset[str]:
    """The fields whose JSON type is integer (alone or beside null)."""
    props = model.model_json_schema()["properties"]
    return frozenset(name for name, prop in props.items()
                     if "integer" in {alt.get("type") for alt in prop.get("anyOf", [prop])})
