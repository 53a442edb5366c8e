"""HEAD and OPTIONS for every route, and one value per query parameter.

FastAPI routes answer only the methods they declare, so HEAD and OPTIONS got
405 (and the 405's Allow named only POST on /v1/render). This middleware
answers HEAD as the GET it mirrors (the server drops the body, the headers stay)
and OPTIONS with 204 and the path's Allow, read from the app's own routes.

A query string may repeat a name; pydantic keeps the last value, so
``mu_f=2000&mu_f=1`` rendered while the other order was refused. A repeated
scalar parameter is now a 422 naming it; only the tuple fields of the query models
(``albedo=R&albedo=G&albedo=B``, ``tangent_axis`` ...) may repeat, read from the models
so that a new tuple field repeats without a change here.

A path with a trailing slash that only has a route without it is a 404 naming that
path, where Starlette redirected to it.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from urllib.parse import parse_qsl

from starlette.applications import Starlette
from starlette.responses import Response
from starlette.routing import Match, Mount
from starlette.types import ASGIApp, Receive, Scope, Send

from opaline.model.params import tuple_fields
from opaline.server.errors import problem
from opaline.server.queries import MdfQuery, RenderQuery

REPEATABLE = tuple_fields(RenderQuery) | tuple_fields(MdfQuery)
PROBED = ("GET", "POST", "PUT", "PATCH", "DELETE")


def allowed_methods(app: Starlette, scope: Scope) -> set[str]:
    """The methods some route of ``app`` answers on this path (HEAD with GET, OPTIONS always).

    Asked of the routes themselves, one method at a time, so included routers count."""
    methods: set[str] = set()
    for route in app.router.routes:
        if isinstance(route, Mount):  # static files: GET (and HEAD) whatever the method
            if route.matches(scope)[0] is not Match.NONE:
                methods.add("GET")
            continue
        methods |= {m for m in PROBED if route.matches({**scope, "method": m})[0] is Match.FULL}
    if "GET" in methods:
        methods.add("HEAD")
    return methods | {"OPTIONS"} if methods else methods


def mismatched(app: Starlette, scope: Scope) -> bool:
    """Whether some route has this path but none this method (one pass, as routing's)."""
    partial = False
    for route in app.router.routes:
        match = route.matches(scope)[0]
        if match is Match.FULL:
            return False
        partial = partial or match is Match.PARTIAL
    return partial


def without_slash(app: Starlette, scope: Scope) -> str | None:
    """The path less its trailing slash where only that has a route. The app does not
    redirect there (redirect_slashes is off): Starlette's redirect wrote the request's
    Host header into its Location, so a forged Host sent clients elsewhere."""
    path = scope["path"]
    if len(path) < 2 or not path.endswith("/") or allowed_methods(app, scope):
        return None
    bare = path.rstrip("/")
    return bare if allowed_methods(app, {**scope, "path": bare}) else None


def repeated(query_string: bytes) -> list[str]:
    """One line per scalar parameter given more than once."""
    counts = Counter(name for name, _ in parse_qsl(query_string.decode("latin-1"),
                                                   keep_blank_values=True))
    return [f"{name}: given {n} times; give each parameter once"
            for name, n in counts.items() if n > 1 and name not in REPEATABLE]


class Methods:
    def __init__(self, app: ASGIApp, routes_of: Starlette, on_reject: Callable[[str], None]
                 ) -> None:
        self.app, self.routes_of, self.on_reject = app, routes_of, on_reject

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        method = scope["method"]
        allowed = (allowed_methods(self.routes_of, scope)
                   if method not in ("GET", "POST") or mismatched(self.routes_of, scope)
                   else None)
        if method == "OPTIONS" and allowed:
            await Response(status_code=204, headers={"Allow": ", ".join(sorted(allowed))})(
                scope, receive, send)
            return
        if method == "HEAD" and allowed and "GET" in allowed:
            scope = {**scope, "method": "GET"}
        elif allowed and method not in allowed:
            # Starlette's 405 names only the first route's methods (POST on /v1/render,
            # and for a GET of a POST route its own "Method Not Allowed")
            self.on_reject("method_not_allowed")
            await problem(405, "method_not_allowed", f"{method} is not allowed here",
                          headers={"Allow": ", ".join(sorted(allowed))})(scope, receive, send)
            return
        bare = without_slash(self.routes_of, scope)
        if bare:
            self.on_reject("not_found")
            await problem(404, "not_found", f"Not Found: did you mean {bare} (without the "
                          "trailing slash)?")(scope, receive, send)
            return
        lines = repeated(scope.get("query_string", b""))
        if lines:
            self.on_reject("invalid")
            await problem(422, "invalid", lines)(scope, receive, send)
            return
        await self.app(scope, receive, send)
