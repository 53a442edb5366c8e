"""The public face of every failure: one body shape, a status, and a count.

Every 4xx and 5xx answers ``{"error": reason, "detail": [line, ...]}``: 422 with
one line per problem, 400 for a body that does not parse, 404 for an unknown
preset, mesh, environment, turntable or path, 413 for a body over the limit, 409
for a turntable still rendering, 429 and 503 with Retry-After, 500 with a pointer
to the server log (the traceback and any shader log go only there).
Each answer is counted under its reason. ``install`` puts the handlers and the
body limit on an app.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel, Field, ValidationError
from starlette.exceptions import HTTPException
from starlette.requests import ClientDisconnect
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from opaline.model.params import RenderRequest, describe_errors
from opaline.model.presets import UnknownPreset
from opaline.model.request import CostError
from opaline.server.meshstore import InvalidMesh, MeshTooLarge, UnknownMesh
from opaline.server.metrics import REJECT_REASONS, Metrics
from opaline.server.queries import Malformed, MdfQuery
from opaline.workers.errors import (
    Cancelled,
    DeadlineExceeded,
    InvalidInput,
    Overloaded,
    RenderFailed,
    TooSlow,
    Unavailable,
)


class LimitError(ValueError):
    """A request within the parameter ranges but over this service's configured limits."""

    def __init__(self, problems: list[str], fields: list[str | None] | None = None) -> None:
        super().__init__("; ".join(problems))
        self.problems = problems
        self.fields = fields or [None] * len(problems)  # the field each problem is about


class UnknownEnvironment(LookupError):
    """An environment name that is neither built in nor a file of the environments folder."""


class UnknownTurntable(LookupError):
    """A turntable id this server does not know (never started, or forgotten)."""


class StillRendering(Exception):
    """The turntable's animation is not ready yet (409)."""


class Busy(Exception):
    """As many turntables as the service runs at once are running (429 with Retry-After)."""

    def __init__(self, message: str, retry_after_s: float = 1.0) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


PUBLIC_ERRORS: dict[type[Exception], tuple[int, str]] = {
    Malformed: (400, "malformed"),
    UnknownPreset: (404, "unknown_preset"),
    CostError: (422, "cost"),
    LimitError: (422, "limit"),
    TooSlow: (422, "too_slow"),
    ValidationError: (422, "invalid"),
    Overloaded: (503, "queue_full"),
    DeadlineExceeded: (503, "deadline"),
    Unavailable: (503, "unavailable"),
    Cancelled: (503, "cancelled"),
    RenderFailed: (500, "render_failed"),
    InvalidInput: (422, "invalid"),
    UnknownMesh: (404, "unknown_mesh"),
    MeshTooLarge: (413, "too_large"),
    InvalidMesh: (422, "invalid_mesh"),
    UnknownEnvironment: (404, "unknown_environment"),
    UnknownTurntable: (404, "unknown_turntable"),
    StillRendering: (409, "rendering"),
    Busy: (429, "busy"),
}


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

# Handlers


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


def _field_of(loc: tuple) -> str | None:
    """The top-level request field of an error location (FastAPI's start with body/query)."""
    loc = loc[1:] if loc and loc[0] in ("body", "query", "path") else loc
    return loc[0] if loc and isinstance(loc[0], str) else None


def _validation_fields(errors: list[dict[str, Any]], model: type[BaseModel],
                       lines_of: Any) -> list[dict[str, str]]:
    """``fields`` of a 422: each error about a field, with the line ``lines_of`` gives it
    alone (the lines are written one per error, so they are those of ``detail``)."""
    found = []
    for err in errors:
        name = _field_of(tuple(err.get("loc", ())))
        if name is not None:
            found.extend({"field": name, "message": line} for line in lines_of([err], model))
    return found


def problem(status: int, reason: str, detail: str | list[str],
            headers: dict[str, str] | None = None,
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


async def on_invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
    code = validation_code(list(exc.errors()))
    request.app.state.metrics.reject(code)
    model = MdfQuery if request.url.path.startswith("/v1/mdf") else RenderRequest
    errors = list(exc.errors())
    return problem(422, code, _validation_lines(errors, model),
                   fields=_validation_fields(errors, model, _validation_lines))


async def on_public_error(request: Request, exc: Exception) -> JSONResponse:
    status, reason = next(v for k, v in PUBLIC_ERRORS.items() if isinstance(exc, k))
    if isinstance(exc, ValidationError):
        reason = validation_code(exc.errors())
    state = request.app.state
    state.metrics.reject(reason)
    if isinstance(exc, ValidationError):
        return problem(status, reason, describe_errors(exc),
                       fields=_validation_fields(exc.errors(), RenderRequest, describe_errors))
    if isinstance(exc, LimitError):
        return problem(status, reason, exc.problems, fields=[
            {"field": name, "message": line}
            for name, line in zip(exc.fields, exc.problems, strict=True) if name is not None])
    if isinstance(exc, RenderFailed):
        return problem(status, reason, f"{exc}: the details are in the server log")
    if status in (429, 503):
        wait = getattr(exc, "retry_after_s", state.settings.retry_after_s)
        retry = str(max(state.settings.retry_after_s, math.ceil(wait)))
        return problem(status, reason, f"{exc}; retry later", headers={"Retry-After": retry})
    return problem(status, reason, str(exc))


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
    return problem(500, "error", "internal error: the details are in the server log")


class BodyLimit:
    """413 for a body over ``limit`` bytes: by its Content-Length, or counted as it arrives."""

    def __init__(self, app: ASGIApp, limit: int, on_reject: Any,
                 paths: dict[str, int] | None = None) -> None:
        self.app, self.limit, self.on_reject = app, limit, on_reject
        self.paths = paths or {}  # routes whose body is a file, with their own limit

    def _refuse(self, limit: int, count: bool = True) -> str:
        """Count the rejection (unless the error handler will); the message to answer it with."""
        if count:
            self.on_reject()
        return f"request body over the {limit} byte limit"

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        limit = self.paths.get(scope.get("path", ""), self.limit)
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared.isdigit() and int(declared) > limit:
            await problem(413, "too_large", self._refuse(limit))(scope, receive, send)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > limit:
                # The route's body reader re-raises it; on_http_error answers and counts it
                raise HTTPException(413, self._refuse(limit, count=False))
            return message

        await self.app(scope, counted, send)


def install(app: FastAPI, max_body_bytes: int, metrics: Metrics,
            file_limits: dict[str, int] | None = None) -> None:
    """The body limit and a handler for every public error, each counting its rejections."""
    app.add_middleware(BodyLimit, limit=max_body_bytes,
                       on_reject=partial(metrics.reject, "too_large"), paths=file_limits)
    app.add_exception_handler(RequestValidationError, on_invalid)
    app.add_exception_handler(HTTPException, on_http_error)
    app.add_exception_handler(ClientDisconnect, on_gone)
    app.add_exception_handler(Exception, on_crash)
    for exc_type in PUBLIC_ERRORS:
        app.add_exception_handler(exc_type, on_public_error)
