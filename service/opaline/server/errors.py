"""The public face of every failure: a status, a message, and whether it is counted.

422 with one line per problem, 404 for an unknown preset, 413 for a body over
the limit, 503 with Retry-After, 500 with a pointer to the server log (the
traceback and any shader log go only there). ``install`` puts the handlers and
the body limit on an app.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import BaseModel, Field, ValidationError
from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from opaline.model.params import RenderRequest, describe_errors
from opaline.model.presets import UnknownPreset
from opaline.model.request import CostError
from opaline.server.meshstore import MeshTooLarge, UnknownMesh
from opaline.server.metrics import Metrics
from opaline.server.queries import MdfQuery
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

    def __init__(self, problems: list[str]) -> None:
        super().__init__("; ".join(problems))
        self.problems = problems


PUBLIC_ERRORS: dict[type[Exception], tuple[int, str | None]] = {
    UnknownPreset: (404, "unknown_preset"),
    CostError: (422, "cost"),
    LimitError: (422, "invalid"),
    TooSlow: (422, "too_slow"),
    ValidationError: (422, "invalid"),
    Overloaded: (503, "queue_full"),
    DeadlineExceeded: (503, "deadline"),
    Unavailable: (503, "unavailable"),
    Cancelled: (503, "cancelled"),
    RenderFailed: (500, None),
    InvalidInput: (422, "invalid"),
    UnknownMesh: (404, "unknown_mesh"),
    MeshTooLarge: (413, "too_large"),
}


# The error bodies as the OpenAPI document shows them


class Problem(BaseModel):
    detail: str


class Problems(BaseModel):
    detail: list[str] = Field(description="One line per problem: field, value, allowed range.")


RETRY_AFTER = {"Retry-After": {"description": "Seconds to wait before retrying.",
                               "schema": {"type": "integer"}}}
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    422: {"model": Problems, "description": "Invalid parameters, or over a configured limit."},
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


def _problem(status: int, detail: str | list[str], headers: dict[str, str] | None = None):
    return JSONResponse({"detail": detail}, status_code=status, headers=headers)


async def on_invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
    request.app.state.metrics.reject("invalid")
    model = MdfQuery if request.url.path.startswith("/v1/mdf") else RenderRequest
    return _problem(422, _validation_lines(list(exc.errors()), model))


async def on_public_error(request: Request, exc: Exception) -> JSONResponse:
    status, reason = next(v for k, v in PUBLIC_ERRORS.items() if isinstance(exc, k))
    state = request.app.state
    if reason:
        state.metrics.reject(reason)
    if isinstance(exc, ValidationError):
        return _problem(status, describe_errors(exc))
    if isinstance(exc, LimitError):
        return _problem(status, exc.problems)
    if isinstance(exc, RenderFailed):
        return _problem(status, f"{exc}: the details are in the server log")
    if status == 503:
        wait = getattr(exc, "retry_after_s", state.settings.retry_after_s)
        retry = str(max(state.settings.retry_after_s, math.ceil(wait)))
        return _problem(status, f"{exc}; retry later", headers={"Retry-After": retry})
    return _problem(status, [str(exc)] if status == 422 else str(exc))


class BodyLimit:
    """413 for a body over ``limit`` bytes: by its Content-Length, or counted as it arrives."""

    def __init__(self, app: ASGIApp, limit: int, on_reject: Any,
                 paths: dict[str, int] | None = None) -> None:
        self.app, self.limit, self.on_reject = app, limit, on_reject
        self.paths = paths or {}  # routes whose body is a file, with their own limit

    def _refuse(self, limit: int) -> str:
        """Count the rejection; the message to answer it with."""
        self.on_reject()
        return f"request body over the {limit} byte limit"

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        limit = self.paths.get(scope.get("path", ""), self.limit)
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared.isdigit() and int(declared) > limit:
            await _problem(413, self._refuse(limit))(scope, receive, send)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > limit:
                # FastAPI re-raises HTTPException from its body reader
                raise HTTPException(413, self._refuse(limit))
            return message

        await self.app(scope, counted, send)


def install(app: FastAPI, max_body_bytes: int, metrics: Metrics,
            file_limits: dict[str, int] | None = None) -> None:
    """The body limit and a handler for every public error, each counting its rejections."""
    app.add_middleware(BodyLimit, limit=max_body_bytes,
                       on_reject=partial(metrics.reject, "too_large"), paths=file_limits)
    app.add_exception_handler(RequestValidationError, on_invalid)
    for exc_type in PUBLIC_ERRORS:
        app.add_exception_handler(exc_type, on_public_error)
