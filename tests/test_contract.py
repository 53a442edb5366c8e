"""The HTTP API is what its OpenAPI document says (issue 11, part 1), through TestClient."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from opaline.model.params import RenderRequest, wavelengths_ok
from opaline.server.api import create_app
from opaline.server.methods import REPEATABLE, repeated
from opaline.server.queries import MdfQuery, RenderQuery
from opaline.settings import Settings

pytestmark = pytest.mark.gl

SMALL = "width=32&height=32&quality=draft"
JSON = {"content-type": "application/json"}


@pytest.fixture(scope="module")
def client(backend):
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1))
    with TestClient(app) as client:
        yield client


def rejected(client: TestClient, reason: str) -> float:
    registry = client.app.state.metrics.registry
    return registry.get_sample_value("opaline_rejected_requests_total", {"reason": reason}) or 0.0


def error(response, status: int, reason: str) -> list[str]:
    """The lines of an error answer, after checking the one shape every error has."""
    assert response.status_code == status, response.text
    body = response.json()
    # A 422 also names the field of each problem about one (the page routes errors by it).
    shape = {"error", "detail", "fields"} if status == 422 else {"error", "detail"}
    assert body["error"] == reason and set(body) == shape, body
    assert body["detail"] and all(isinstance(line, str) for line in body["detail"]), body
    return body["detail"]


# Strict types


@pytest.mark.parametrize("body", [b'{"mu_f": "6"}', b'{"mu_f": false}', b'{"transparent": 1}',
                                  b'{"width": "64"}', b'{"samples": 4.5}', b'{"format": 3}'])
def test_body_numbers_and_booleans_must_be_json_ones(client, body):
    """A string, a boolean or a fraction where the schema says number/integer/boolean is 422."""
    name = body.decode().split('"')[1]
    lines = error(client.post("/v1/render", content=body, headers=JSON), 422, "invalid")
    assert any(line.startswith(name) for line in lines), lines


def test_integral_float_is_an_integer_as_json_schema_says(client):
    """JSON Schema's integer includes 32.0, so a body may write sizes that way."""
    response = client.post("/v1/render", json={"width": 32.0, "height": 32, "quality": "draft"})
    assert response.status_code == 200, response.text


@pytest.mark.parametrize(("path", "body", "name"), [
    ("/v1/render", b'{"mu_f": 2000, "preset": "sphere", "mu_f": 1}', "mu_f"),
    ("/v1/render", b'{"width": 32, "width": 32}', "width"),
    ("/v1/turntables", b'{"frames": 4, "quality": "draft", "quality": "high"}', "quality"),
    ("/v1/export/glb", b'{"preset": "sphere", "a b": 1, "a b": 2}', '"a b"')])
def test_a_key_given_twice_in_the_body_is_422_naming_it(client, path, body, name):
    """{"mu_f": 2000, "mu_f": 1} was a 200 that used the last (pydantic's parser keeps it),
    though the first is out of range: which one counts is the parser's choice (RFC 8259
    §4). Now refused, with the key named."""
    answer = client.post(path, content=body, headers=JSON)
    (line,) = error(answer, 422, "invalid")
    assert line.startswith(f"{name}: given more than once"), line
    # fields names it too (it was empty): the key as written, not as the message quotes it
    assert answer.json()["fields"] == [{"field": name.strip('"'), "message": line}]


@pytest.mark.parametrize(("body", "words"), [
    (b"\xff\xfe{}", "UTF-8"),
    (b"[" * 300 + b"]" * 300, "recursion"),
    (b'{"mu_f": 1', "JSON"),
    (b"", "JSON object is required"),
])
def test_unparsable_body_is_400_in_the_public_shape_and_counted(client, body, words):
    """Bad UTF-8, nesting past the parser's depth and malformed JSON: 400, counted."""
    before = rejected(client, "malformed")
    (line,) = error(client.post("/v1/render", content=body, headers=JSON), 400, "malformed")
    assert words in line
    assert rejected(client, "malformed") == before + 1


# Query strings


@pytest.mark.parametrize("query", ["mu_f=2000&mu_f=1", "mu_f=1&mu_f=2000", "width=32&width=32"])
def test_repeated_scalar_parameter_is_422_naming_it(client, query):
    """Either order of a repeated parameter is refused (pydantic alone keeps the last)."""
    name = query.split("=")[0]
    (line,) = error(client.get(f"/v1/render?{query}"), 422, "invalid")
    assert line.startswith(f"{name}: given 2 times")


def test_albedo_may_repeat(client):
    response = client.get(f"/v1/render?{SMALL}&albedo=0.1&albedo=0.2&albedo=0.3")
    assert response.status_code == 200


def test_every_tuple_field_may_repeat_or_be_comma_separated():
    """The repeatable names come from the models: a new tuple field needs no change."""
    assert {"albedo", "tangent_axis"} <= REPEATABLE
    assert "mu_f" not in REPEATABLE
    assert not repeated(b"tangent_axis=1&tangent_axis=0&tangent_axis=0&albedo=0.1")
    spelled = (RenderQuery(tangent_axis="1,0,0").tangent_axis,
               RenderQuery(tangent_axis=["1", "0", "0"]).tangent_axis)
    assert spelled == ((1.0, 0.0, 0.0), (1.0, 0.0, 0.0))


# Methods


@pytest.mark.parametrize("path", ["/healthz", "/readyz", "/v1/presets", "/v1/presets/sphere",
                                  f"/v1/render?{SMALL}", "/v1/mdf?size=16", "/openapi.json",
                                  "/docs", "/metrics", "/"])
def test_head_mirrors_every_get(client, path):
    """HEAD answers what GET does, with the same headers and no body."""
    get, head = client.get(path), client.head(path)
    assert head.status_code == get.status_code == 200 and head.content == b""
    assert head.headers["content-type"] == get.headers["content-type"]


@pytest.mark.parametrize(("path", "allow"), [
    ("/v1/render", "GET, HEAD, OPTIONS, POST"), ("/v1/mdf", "GET, HEAD, OPTIONS"),
    ("/healthz", "GET, HEAD, OPTIONS"), ("/v1/presets/sphere", "GET, HEAD, OPTIONS")])
def test_options_and_405_name_every_method_of_the_path(client, path, allow):
    options = client.options(path)
    assert options.status_code == 204 and options.headers["allow"] == allow
    wrong = client.delete(path)
    error(wrong, 405, "method_not_allowed")
    assert wrong.headers["allow"] == allow


@pytest.mark.parametrize(("method", "path", "allow"), [
    ("GET", "/v1/meshes", "OPTIONS, POST"), ("HEAD", "/v1/turntables", "OPTIONS, POST"),
    ("POST", "/v1/mdf", "GET, HEAD, OPTIONS"), ("POST", "/healthz", "GET, HEAD, OPTIONS"),
    ("POST", "/v1/presets", "GET, HEAD, OPTIONS")])
def test_a_get_or_post_of_the_other_kind_of_route_is_the_same_405(client, method, path, allow):
    """GET of a POST route, HEAD of one, POST of a GET route: Starlette's own 405 named
    only that route's methods ("allow: POST") with its "Method Not Allowed"."""
    wrong = client.request(method, path)
    assert wrong.status_code == 405 and wrong.headers["allow"] == allow
    if method != "HEAD":
        assert wrong.json() == {"error": "method_not_allowed",
                                "detail": [f"{method} is not allowed here"]}


def test_unknown_path_is_404_in_the_public_shape(client):
    error(client.get("/v2/nothing"), 404, "not_found")
    error(client.options("/v2/nothing"), 404, "not_found")


@pytest.mark.parametrize("path", ["/v1/render/", "/v1/presets/", "/v1/meshes/"])
def test_a_trailing_slash_is_not_redirected_to_the_clients_host(client, path):
    """Starlette answered /v1/render/ with a 307 to http://{the request's Host}/v1/render:
    a forged Host made the service point clients elsewhere (a review found it). Now a 404
    that names the path to use."""
    response = client.get(path, headers={"host": "evil.example"}, follow_redirects=False)
    (line,) = error(response, 404, "not_found")
    assert "location" not in response.headers
    assert f"did you mean {path.rstrip('/')} " in line


# The document says exactly what is validated


def schema_accepts(schema: dict, n: int) -> bool:
    """The few JSON Schema words the wavelengths schema uses, applied to an integer."""
    if n < schema.get("minimum", -1e9) or n > schema.get("maximum", 1e9):
        return False
    return n not in schema.get("not", {}).get("enum", [])


def validates(model, n: int) -> bool:
    try:
        model.model_validate({"wavelengths": n})
    except ValueError:
        return False
    return True


def test_wavelengths_schema_is_exactly_what_the_models_accept(client):
    """For every count from -1 to 200 the OpenAPI schema (body and both query forms) accepts
    it if and only if the models do, whatever wavelengths_ok decides."""
    spec = client.get("/openapi.json").json()
    body = spec["components"]["schemas"]["RenderRequest"]["properties"]["wavelengths"]
    queries = {path: next(p["schema"] for p in spec["paths"][path]["get"]["parameters"]
                          if p["name"] == "wavelengths") for path in ("/v1/render", "/v1/mdf")}
    for n in range(-1, 201):
        ok = validates(RenderRequest, n)
        assert ok == validates(RenderQuery, n) == validates(MdfQuery, n)
        assert schema_accepts(body, n) == ok, n
        assert schema_accepts(queries["/v1/render"], n) == schema_accepts(queries["/v1/mdf"], n) == ok
        assert ok == (wavelengths_ok(n) == n if ok else False)


def test_every_error_status_is_documented_with_the_problem_shape(client):
    """Every documented 4xx/5xx is a Problem, but /readyz's 503 (a probe's answer: the
    workers' states, the same body as its 200)."""
    spec = client.get("/openapi.json").json()
    for path, methods in spec["paths"].items():
        for method, operation in methods.items():
            for status, answer in operation["responses"].items():
                if status[0] in "45" and (path, status) != ("/readyz", "503"):
                    ref = answer["content"]["application/json"]["schema"]["$ref"]
                    assert ref.endswith("/Problem"), (path, method, status)
    assert "HTTPValidationError" not in spec["components"]["schemas"]


def test_a_long_unknown_name_is_not_echoed_whole(client):
    """A 60 KB unknown query name was echoed whole in detail and twice in fields."""
    answer = client.get("/v1/render?" + "x" * 60000 + "=1")
    assert answer.status_code == 422 and len(answer.content) < 4096
    assert answer.json()["fields"][0]["field"] == "x" * 63 + "…"
    assert answer.json()["detail"][0].startswith("x" * 63 + "…: unknown field")
