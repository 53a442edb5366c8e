"""A query-string model read in one step: what FastAPI's ``Annotated[Model, Query()]``
does, at a hundredth of the cost.

FastAPI reads a query model field by field and inspects each field's type again
on every request: 0.2 ms for the 47 fields of GET /v1/render on an idle core, a
fifth of the service's own time on a cache miss (docs/speed.md, "The path around
the render"). ``query_model(Model)`` is a dependency that gathers the same
values (a tuple field every repeat, another field its last value, an unknown
name its value or values, for the model to refuse), validates them in one call
and raises the same ``RequestValidationError``. ``documented(Model)`` is the
route's ``openapi_extra``: the parameters FastAPI itself writes for the model.
"""

from __future__ import annotations

import inspect
from collections.abc import Awaitable, Callable, Mapping
from typing import Annotated, Any, TypeVar

from fastapi import FastAPI, Query, Request
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, ValidationError

from opaline.model.params import tuple_fields

Model = TypeVar("Model", bound=BaseModel)


def gather(fields: Mapping[str, Any], repeatable: frozenset[str],
           items: list[tuple[str, str]]) -> dict[str, Any]:
    """The values FastAPI would hand a model with these fields for these query items."""
    values: dict[str, Any] = {}
    extras: dict[str, list[str]] = {}
    for name, value in items:
        if name in repeatable:
            values.setdefault(name, []).append(value)
        elif name in fields:
            values[name] = value
        else:
            extras.setdefault(name, []).append(value)
    values.update((name, found[0] if len(found) == 1 else found)
                  for name, found in extras.items())
    return values


def query_model(model: type[Model]) -> Callable[[Request], Awaitable[Model]]:
    """A dependency answering the request's query string as ``model`` (422 if invalid)."""

    fields, repeatable = model.model_fields, tuple_fields(model)

    async def parse(request: Request) -> Model:
        try:
            return model.model_validate(gather(fields, repeatable,
                                               request.query_params.multi_items()))
        except ValidationError as exc:
            raise RequestValidationError(
                [{**err, "loc": ("query", *err["loc"])}
                 for err in exc.errors(include_url=False)]) from None

    return parse


def documented(model: type[BaseModel]) -> dict[str, Any]:
    """``openapi_extra`` naming the parameters FastAPI itself documents for ``model``:
    a throwaway app's schema (about 30 ms, once, as the routes are declared)."""

    async def route(**_: Any) -> None: ...

    # FastAPI reads a route's parameters through inspect, which honours __signature__;
    # typeshed's function type does not declare the attribute.
    route.__signature__ = inspect.Signature([inspect.Parameter(  # type: ignore[attr-defined]
        "query", inspect.Parameter.KEYWORD_ONLY, annotation=Annotated[model, Query()])])
    probe = FastAPI()
    probe.add_api_route("/", route)
    return {"parameters": probe.openapi()["paths"]["/"]["get"]["parameters"]}
