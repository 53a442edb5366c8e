"""The public face of every failure: one body shape, a status, and a count.

Every 4xx and 5xx answers ``{"error": reason, "detail": [line, ...]}``: 422 with
one line per problem, 400 for a body that does not parse, 404 for an unknown
preset, mesh, environment, turntable or path, 413 for a body over the limit, 409
for a turntable still rendering, 429 and 503 with Retry-After, 500 with a pointer
to the server log (the traceback and any shader log go only there).
Each failure of this package is an ``opaline.errors.PublicError`` that names its
own status, reason and lines; ``on_public_error`` answers them all. Each answer is
counted under its reason. ``install`` puts the handlers on an app (the body limit is
``body_limit.BodyLimit``).
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Mapping, Sequence
from typing import Any, TypeVar

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel, Field, ValidationError
from starlette.exceptions import HTTPException
from starlette.requests import ClientDisconnect

from opaline.errors import PublicError
from opaline.model.messages import UNKNOWN_NAMED, shown_name
from opaline.model.params import RenderRequest, describe_errors
from opaline.model.turntable import TurntableRequest
from opaline.pipeline.limits import LimitError as LimitError
from opaline.pipeline.prepare import UnknownEnvironment as UnknownEnvironment
from opaline.server.docs import SECURITY_HEADERS
from opaline.server.metrics import REJECT_REASONS
from opaline.server.queries import MdfQuery


class UnknownTurntable(PublicError, LookupError):
    """A turntable id this server does not know (never started, or forgotten)."""

    status, reason = 404, "unknown_turntable"


class StillRendering(PublicError):
    """The turntable's animation is not ready yet (409)."""

    status, reason = 409, "rendering"


class Busy(PublicError):
    """As many turntables as the service runs at once are running (429 with Retry-After)."""

    status, reason, retry_later = 429, "busy", True

    retry_after_s: float

    def __init__(self, message: str, retry_after_s: float = 1.0) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


# The error bodies as the OpenAPI document shows them


class FieldProblem(BaseModel):
    """One line of a 422's detail with the request field it is about."""

    field: str = Field(description="The request field (top level: albedo for albedo.0).")
    message: str = Field(description="Its line of detail, as written there.")


class Problem(BaseModel):
    """Every error answer, whatever its status."""

    error: str = Field(description="Why, in one word: " + ", ".join(REJECT_REASONS) + ".")
    detail: list[str] = Field(description="One line per problem: field, value, what is allowed.")
    fields: list[FieldProblem] = Field(
        default_factory=list, description="422 only: the problems that are about one request "
                                          "field, each with its line of detail.")


# Reasons of the errors Starlette raises itself (routing, body limit, access control).
HTTP_REASONS = {400: "malformed", 403: "forbidden", 404: "not_found",
                405: "method_not_allowed", 408: "timeout", 413: "too_large",
                429: "rate_limited"}
RETRY_AFTER = {"Retry-After": {"description": "Seconds to wait before retrying.",
                               "schema": {"type": "integer"}}}
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    400: {"model": Problem, "description": "The body is not a JSON document (not UTF-8, not "
                                           "JSON, or nested too deep)."},
    403: {"model": Problem, "description": "Access control is on and the request has no valid "
                                           "API key or URL signature."},
    404: {"model": Problem, "description": "Unknown preset (the message lists the valid ones), "
                                           "mesh, environment or path."},
    413: {"model": Problem, "description": "Request body too large."},
    422: {"model": Problem, "description": "Invalid parameters, or over a configured limit."},
    429: {"model": Problem, "description": "Over the rate limit.", "headers": RETRY_AFTER},
    503: {"model": Problem, "description": "Overloaded or no GL context.", "headers": RETRY_AFTER},
    500: {"model": Problem, "description": "The render failed (details in the server log)."},
}

# What a route with a JSON body adds (queries.require_json).
JSON_BODY_RESPONSES: dict[int | str, dict[str, Any]] = {
    415: {"model": Problem, "description": "The body is labelled as something other than "
                                           "JSON (send content-type: application/json)."},
}

# Handlers


# describe_errors or _validation_lines: an errors() list and a model → one line per error
LinesOf = Callable[[list[Any], type[BaseModel]], list[str]]


def _validation_lines(errors: list[dict[str, Any]], model: type[BaseModel]) -> list[str]:
    """describe_errors' lines for FastAPI's errors, whose locations start with 'body'/'query'."""
    lines, rest = [], []
    for err in errors:
        loc = tuple(err.get("loc", ()))
        loc = loc[1:] if loc and loc[0] in ("body", "query", "path") else loc
        if err["type"] == "json_invalid":
            reason = (err.get("ctx") or {}).get("error", "")
            lines.append(f"body: not valid JSON ({reason})" if reason else "body: not valid JSON")
        elif not loc and err["type"] == "missing":
            lines.append("body: a JSON object is required ({} renders the defaults)")
        else:
            rest.append({**err, "loc": () if loc and isinstance(loc[0], int) else loc})

    return lines + describe_errors(rest, model)


def _field_of(loc: tuple[str | int, ...]) -> str | None:
    """The top-level request field of an error location (FastAPI's start with body/query)."""
    loc = loc[1:] if loc and loc[0] in ("body", "query", "path") else loc
    return loc[0] if loc and isinstance(loc[0], str) else None


def _validation_fields(errors: Sequence[Mapping[str, Any]], model: type[BaseModel],
                       lines_of: LinesOf) -> list[dict[str, str]]:
    """``fields`` of a 422: each error about a field, with the line ``lines_of`` gives it
    alone (the lines are written one per error, so they are those of ``detail``)."""
    found: list[dict[str, str]] = []
    unknown = 0
    for err in errors:
        name = _field_of(tuple(err.get("loc", ())))
        if err.get("type") == "extra_forbidden":
            unknown += 1
            if unknown > UNKNOWN_NAMED:  # as many as detail names; it counts the rest
                continue
        if name is not None:
            found.extend({"field": shown_name(name), "message": line}
                         for line in lines_of([err], model))
    return found


def problem(status: int, reason: str, detail: str | list[str],
            headers: Mapping[str, str] | None = None,
            fields: list[dict[str, str]] | None = None) -> JSONResponse:
    """The one error body: ``{"error": reason, "detail": [lines]}``; a 422's also has
    ``fields``, its problems about a request field (``[{"field": name, "message": line}]``)."""
    lines = [detail] if isinstance(detail, str) else detail
    body: dict[str, Any] = {"error": reason, "detail": lines}
    if status == 422:
        body["fields"] = fields or []
    return JSONResponse(body, status_code=status, headers=headers)


def validation_code(errors: list[Any]) -> str:
    """``budget_with_tier`` when that cross-field rule is the only problem, else ``invalid``."""
    kinds = {err.get("type") for err in errors}
    return "budget_with_tier" if kinds == {"budget_with_tier"} else "invalid"


def _model_for(path: str) -> type[BaseModel]:
    """The model a route's fields come from, whose ranges its error lines give."""
    if path.startswith("/v1/mdf"):
        return MdfQuery
    return TurntableRequest if path.startswith("/v1/turntables") else RenderRequest


async def on_invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
    code = validation_code(list(exc.errors()))
    request.app.state.metrics.reject(code)
    model = _model_for(request.url.path)
    errors = list(exc.errors())
    return problem(422, code, _validation_lines(errors, model),
                   fields=_validation_fields(errors, model, _validation_lines))


async def on_public_error(request: Request, exc: PublicError) -> JSONResponse:
    """Any failure of this package, as it says it is answered."""
    settings = request.app.state.settings
    request.app.state.metrics.reject(exc.reason)
    return problem(exc.status, exc.reason, exc.lines(), exc.headers(settings.retry_after_s),
                   fields=exc.field_problems())


async def on_invalid_model(request: Request, exc: ValidationError) -> JSONResponse:
    """A model that a route validated itself (a strictly parsed body)."""
    reason = validation_code(exc.errors())
    request.app.state.metrics.reject(reason)
    model = _model_for(request.url.path)
    return problem(422, reason, describe_errors(exc, model),
                   fields=_validation_fields(exc.errors(), model, describe_errors))


async def on_http_error(request: Request, exc: HTTPException) -> JSONResponse:
    """Starlette's own errors (404, 405 with its Allow, 413 while streaming) in the same shape."""
    reason = HTTP_REASONS.get(exc.status_code, "invalid" if exc.status_code < 500 else "error")
    request.app.state.metrics.reject(reason)
    return problem(exc.status_code, reason, str(exc.detail), headers=exc.headers)


async def on_gone(request: Request, exc: ClientDisconnect) -> Response:
    """The client left (or was dropped for a slow body) while its body was read: no one to
    answer, nothing to log."""
    return Response(status_code=400)


async def on_crash(request: Request, exc: Exception) -> JSONResponse:
    """A bug: 500 in the public shape; the traceback goes to the log (Starlette logs it)."""
    request.app.state.metrics.reject("error")
    # Starlette answers this from its outermost layer, past the security headers'
    # middleware, then re-raises, and the server drops the connection: say so.
    return problem(500, "error", "internal error: the details are in the server log",
                   headers={**SECURITY_HEADERS, "Connection": "close"})


def install(app: FastAPI) -> None:
    """A handler for every public error, each counting its rejections."""
    _handle(app, RequestValidationError, on_invalid)
    _handle(app, ValidationError, on_invalid_model)
    _handle(app, PublicError, on_public_error)
    _handle(app, HTTPException, on_http_error)
    _handle(app, ClientDisconnect, on_gone)
    _handle(app, Exception, on_crash)


E = TypeVar("E", bound=Exception)


def _handle(app: FastAPI, kind: type[E], handler: Callable[[Request, E], Awaitable[Response]]
            ) -> None:
    # Starlette calls a handler with the class it was registered for, but its stubs type
    # every handler as taking any Exception, so no narrower handler fits them.
    app.add_exception_handler(kind, handler)  # type: ignore[arg-type]
