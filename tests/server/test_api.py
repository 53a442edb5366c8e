"""The HTTP API through FastAPI's TestClient, entered as a context manager so the lifespan runs."""

from __future__ import annotations

import io
import logging
import re
import threading
import time
from functools import partial
from pathlib import Path

import numpy as np
import pytest
from fastapi import FastAPI
from fastapi.testclient import TestClient
from PIL import Image

from opaline.errors import PublicError
from opaline.model.params import RenderFields, field_range
from opaline.model.presets import all_presets
from opaline.model.tiers import TIERS
from opaline.server.api import WEB_DIR, create_app, mount_web
from opaline.server.docs import SecurityHeaders
from opaline.server.errors import HTTP_REASONS
from opaline.server.metrics import REJECT_REASONS
from opaline.settings import MAX_PIXELS, Settings, get_settings
from worker_helpers import BrokenRenderer, EchoTask, GateTask, LostContextRenderer, no_gl

pytestmark = pytest.mark.gl

SMALL = "width=64&height=64&quality=draft"
WAIT = 20.0


@pytest.fixture(scope="module")
def settings(backend) -> Settings:
    return Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1, queue_size=8)


@pytest.fixture(scope="module")
def client(settings):
    with TestClient(create_app(settings)) as client:
        yield client


def make_client(backend, **overrides) -> TestClient:
    overrides.setdefault("calibrate", False)
    return TestClient(create_app(Settings(gl_backend=backend, warmup=False, **overrides)))


def sample(client: TestClient, name: str, labels: dict[str, str] | None = None) -> float:
    value = client.app.state.metrics.registry.get_sample_value(name, labels or {})
    return value or 0.0


def scraped(client: TestClient, name: str) -> float:
    """The value of an unlabelled sample as GET /metrics shows it."""
    for line in client.get("/metrics").text.splitlines():
        if line.startswith(name + " "):
            return float(line.split()[1])
    raise AssertionError(f"{name} is not on /metrics")


def occupy(client: TestClient, folder, key: str = "gate") -> GateTask:
    gate = GateTask(str(folder))
    client.app.state.pool.submit(key, gate)
    gate.wait_entered()
    return gate


def problems(response) -> list[str]:
    """The lines of an error answer, checking its one shape: {"error": reason, "detail": [...]},
    and on a 422 the problems about a field, each a line of detail, under "fields"."""
    body = response.json()
    shape = {"error", "detail", "fields"} if response.status_code == 422 else {"error", "detail"}
    assert set(body) == shape and isinstance(body["error"], str), body
    assert all(isinstance(line, str) for line in body["detail"]), body
    if response.status_code == 422:
        assert all(set(f) == {"field", "message"} and f["message"] in body["detail"]
                   for f in body["fields"]), body
    return body["detail"]


# Operations


def test_healthz(client):
    """/healthz answers 200 while the process is alive."""
    assert client.get("/healthz").json() == {"status": "ok"}


def test_readyz_reports_the_gl_context(client, backend):
    """/readyz is 200 with the worker's backend and GL renderer string."""
    body = client.get("/readyz").json()
    assert body["ready"] is True and body["backend"] == backend
    assert body["renderer"] and body["workers"][0]["state"] == "ready"
    assert body["workers"][0]["pid"] > 0 and body["workers"][0]["rss_bytes"] > 0


def test_readyz_is_503_without_a_context(backend):
    """/readyz is 503 when no worker could make a GL context, and renders answer 503."""
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=False),
                     renderer_factory=no_gl)
    with TestClient(app) as client:
        assert client.get("/readyz").status_code == 503
        response = client.get(f"/v1/render?{SMALL}")
        assert response.status_code == 503 and "Retry-After" in response.headers


def test_metrics_exposition(client):
    """/metrics exposes render latency by preset, cache hits and misses, queue depth, rejections."""
    client.get(f"/v1/render?preset=nacre&{SMALL}&mu_f=4.25")
    client.get(f"/v1/render?preset=nacre&{SMALL}&mu_f=4.25")
    client.get("/v1/render?mu_f=-1")
    text = client.get("/metrics").text
    assert 'opaline_render_seconds_count{preset="nacre"}' in text
    assert "opaline_queue_depth" in text
    assert sample(client, "opaline_cache_hits_total") >= 1
    assert sample(client, "opaline_cache_misses_total") >= 1
    assert sample(client, "opaline_rejected_requests_total", {"reason": "invalid"}) >= 1


def test_every_rejection_reason_is_exposed_from_the_start():
    """Each reason the error handlers count is on /metrics at 0 before the first rejection."""
    def public(cls: type[PublicError]) -> set[type[PublicError]]:
        return {cls}.union(*(public(sub) for sub in cls.__subclasses__()))

    counted = {error.reason for error in public(PublicError)} | set(HTTP_REASONS.values())
    # "budget_with_tier" is the validation handlers' own code for that one cross-field rule.
    assert counted | {"error", "budget_with_tier"} == set(REJECT_REASONS)


# Images


def test_get_render_png(client):
    """GET /v1/render gives a PNG of the requested size with a strong ETag and Cache-Control."""
    response = client.get(f"/v1/render?preset=cd-rom&mu_f=8.5&{SMALL}")
    assert response.status_code == 200 and response.headers["content-type"] == "image/png"
    assert Image.open(io.BytesIO(response.content)).size == (64, 64)
    tag = response.headers["etag"]
    assert tag.startswith('"') and not tag.startswith("W/")
    assert response.headers["cache-control"].startswith("public, max-age=")


def test_post_render_npy(client):
    """POST /v1/render with format npy gives linear float32 RGBA as application/x-npy."""
    body = {"preset": "sphere", "width": 32, "height": 48, "quality": "draft", "format": "npy"}
    response = client.post("/v1/render", json=body)
    assert response.headers["content-type"] == "application/x-npy"
    array = np.load(io.BytesIO(response.content))
    assert array.shape == (48, 32, 4) and array.dtype == np.float32
    assert np.isfinite(array).all() and array.max() > 0


def test_get_and_post_give_the_same_image(client):
    """The same parameters by query string or JSON body give the same bytes and ETag."""
    got = client.get(f"/v1/render?preset=oil-slick&{SMALL}&albedo=0.1,0.2,0.3&theta1=0.5")
    posted = client.post("/v1/render", json={"preset": "oil-slick", "width": 64, "height": 64,
                                             "quality": "draft", "albedo": [0.1, 0.2, 0.3],
                                             "theta1": 0.5})
    assert got.content == posted.content and got.headers["etag"] == posted.headers["etag"]


def test_albedo_query_forms_agree(client):
    """albedo=R,G,B and albedo repeated three times name the same image."""
    one = client.get(f"/v1/render?{SMALL}&kd=1&albedo=0.9,0.2,0.1")
    three = client.get(f"/v1/render?{SMALL}&kd=1&albedo=0.9&albedo=0.2&albedo=0.1")
    assert one.status_code == three.status_code == 200
    assert one.headers["etag"] == three.headers["etag"]


def test_parameters_change_the_image(client):
    """A different material gives different bytes and a different ETag."""
    a = client.get(f"/v1/render?preset=cd-rom&{SMALL}&mu_f=2")
    b = client.get(f"/v1/render?preset=cd-rom&{SMALL}&mu_f=9")
    assert a.content != b.content and a.headers["etag"] != b.headers["etag"]


def test_repeated_get_with_etag_is_304(client):
    """A GET whose If-None-Match holds the ETag answers 304 with no body; another tag gets 200."""
    url = f"/v1/render?preset=sphere&{SMALL}&mu_f=3.5"
    first = client.get(url)
    tag = first.headers["etag"]
    again = client.get(url, headers={"If-None-Match": tag})
    assert again.status_code == 304 and again.content == b""
    assert again.headers["etag"] == tag and "max-age" in again.headers["cache-control"]
    assert client.get(url, headers={"If-None-Match": f'"other", W/{tag}'}).status_code == 304
    assert client.get(url, headers={"If-None-Match": '"other"'}).status_code == 200


def test_mdf_plot_png_and_npy(client):
    """GET /v1/mdf gives the N×N plot: PNG to view, npy of linear D (0 outside the disc)."""
    png = client.get("/v1/mdf?mdf=ashikhmin&ex=100&ey=10&size=64")
    assert png.headers["content-type"] == "image/png"
    assert Image.open(io.BytesIO(png.content)).size == (64, 64)
    raw = client.get("/v1/mdf?mu_f=5&alpha=1&beta=0.1&size=32&format=npy")
    plot = np.load(io.BytesIO(raw.content))
    assert plot.shape == (32, 32, 3) and plot[0, 0].max() == 0 and plot.max() > 0
    assert "etag" in raw.headers


def test_a_field_the_plot_does_not_read_gives_no_second_url(client):
    """kd, a film's index, a tangent axis leave the plot alone: it had one image under as
    many URLs and revs as such fields were spelled (the ETag alone was the same)."""
    plain = client.get("/v1/mdf?size=32&mu_f=3")
    for extra in ("kd=3", "film_ior=2", "iridescence=thin-film", "coat_weight=1"):
        other = client.get(f"/v1/mdf?size=32&mu_f=3&{extra}")
        assert other.status_code == 200
        assert other.headers["content-location"] == plain.headers["content-location"]
        assert other.headers["etag"] == plain.headers["etag"]
    moved = client.get("/v1/mdf?size=32&mu_f=4")
    assert moved.headers["content-location"] != plain.headers["content-location"]


def test_presets_list(client):
    """GET /v1/presets lists every preset with description, figure, geometry and defaults."""
    listed = {p["name"]: p for p in client.get("/v1/presets").json()}
    assert set(listed) == set(all_presets())
    cd = listed["cd-rom"]
    assert cd["description"] and cd["figure"] and cd["geometry"]["kind"]
    assert cd["defaults"]["mu_f"] == 8.5 and cd["resolved"]["material"]["mu_f"] == 8.5


def test_preset_detail(client):
    """GET /v1/presets/{name} gives that preset's resolved defaults."""
    body = client.get("/v1/presets/oil-slick").json()
    assert body["name"] == "oil-slick" and body["resolved"]["width"] == 256


def test_root_serves_the_web_page_or_the_docs(client):
    """/ serves opaline/server/web/index.html when the package has it, else redirects to /docs."""
    response = client.get("/", follow_redirects=False)
    if (WEB_DIR / "index.html").is_file():
        assert response.status_code == 200 and "text/html" in response.headers["content-type"]
    else:
        assert response.status_code in (302, 307) and response.headers["location"] == "/docs"


def test_root_redirects_to_docs_without_web_page(tmp_path):
    """Without index.html in the web folder, / redirects to /docs and /static does not exist."""
    app = FastAPI()
    mount_web(app, tmp_path)
    with TestClient(app) as client:
        response = client.get("/", follow_redirects=False)
        assert response.status_code in (302, 307) and response.headers["location"] == "/docs"
        assert client.get("/static/app.js").status_code == 404


def test_web_page_served_when_present(tmp_path):
    """With a web folder holding index.html, / serves it and /static serves its files."""
    (tmp_path / "index.html").write_text("<h1>Opaline</h1>")
    (tmp_path / "app.js").write_text("console.log(1)")
    app = FastAPI()
    mount_web(app, tmp_path)
    with TestClient(app) as client:
        assert client.get("/").text == "<h1>Opaline</h1>"
        assert client.get("/static/app.js").text == "console.log(1)"


# Bad input


@pytest.mark.parametrize(("query", "field", "allowed"), [
    ("mu_f=2000", "mu_f=", "[0 … 1000]"),
    ("theta1=7", "theta1=", "2π"),
    ("width=8", "width=", "[16 … 2048]"),
    ("samples=0", "samples=", "[1 … 1024]"),
    ("albedo=0.1,2,0.3", "albedo", "[0 … 1]"),
    ("wavelengths=3", "wavelengths=", "4 … 128"),
    ("exposure=0", "exposure=", "(0 … 1000]"),
    ("environment_blur=1.5", "environment_blur=", "[0 … 1]"),
])
def test_out_of_range_query_is_422_naming_field_and_range(client, query, field, allowed):
    """An out-of-range parameter answers 422, naming the field, the value and the range."""
    response = client.get(f"/v1/render?{query}")
    assert response.status_code == 422
    lines = problems(response)
    assert any(field in line and allowed in line for line in lines), lines


def test_422_names_the_field_of_each_problem(client):
    """A 422's "fields" pair each problem about a field with its line (the page routes them
    to its controls); a line about no field (a missing body's) is in detail only."""
    body = client.get("/v1/render?mu_f=2000&albedo=0.1,2,0.3&muf=3").json()
    assert [f["field"] for f in body["fields"]] == ["mu_f", "albedo", "muf"], body
    assert [f["message"] for f in body["fields"]] == body["detail"]
    posted = client.post("/v1/render", json={"ks": 200, "albedo": [0.1, 0.2]}).json()
    assert {f["field"] for f in posted["fields"]} == {"ks", "albedo"}, posted
    mdf = client.get("/v1/mdf?size=4096").json()
    assert [f["field"] for f in mdf["fields"]] == ["size"], mdf


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_query_is_422(client, value):
    """Non-finite numbers in the query string are refused, naming the field."""
    response = client.get(f"/v1/render?mu_f={value}")
    assert response.status_code == 422
    assert any("mu_f" in line and "finite" in line for line in problems(response))


@pytest.mark.parametrize("body", [b'{"ks": NaN}', b'{"ks": Infinity}', b'{"ks": 1e999}'])
def test_non_finite_body_is_422(client, body):
    """Non-finite numbers in a JSON body are refused, naming the field and its range."""
    response = client.post("/v1/render", content=body,
                           headers={"content-type": "application/json"})
    assert response.status_code == 422
    assert any(line.startswith("ks=") and "[0 … 100]" in line for line in problems(response))


def test_unknown_query_field_is_422(client):
    """An unknown query parameter is refused, and the message lists the known ones."""
    lines = problems(client.get("/v1/render?muf=3"))
    assert any("muf" in line and "unknown" in line and "mu_f" in line for line in lines)


def test_many_unknown_query_fields_get_a_short_answer(client):
    """12,000 unknown parameters in a 97 KB query made a 19 MB answer (each line, and each
    entry of ``fields``, listed every known field) that held the server for seconds: now
    five are named, the rest counted. (6,000 here: httpx refuses longer URLs.)"""
    query = "&".join(f"x{i}=1" for i in range(6000))
    response = client.get(f"/v1/render?preset=cd-rom&{query}")
    assert response.status_code == 422
    assert len(response.content) < 20_000
    body = response.json()
    assert body["detail"][-1] == "… and 5995 more unknown fields"
    assert [entry["field"] for entry in body["fields"]] == [f"x{i}" for i in range(5)]


@pytest.mark.parametrize("path", ["/v1/render", "/v1/turntables", "/v1/export/glb"])
def test_a_post_refuses_fields_in_its_query_string(client, path):
    """A POST reads its fields from the body: POST /v1/render?mu_f=2000 with a valid body
    was a 200 that silently did not use mu_f (a review found it). Now a 422 naming it."""
    response = client.post(f"{path}?mu_f=2000&width=64", json={"preset": "sphere"})
    assert response.status_code == 422, response.text
    line = response.json()["detail"][0]
    assert "mu_f, width" in line and "JSON body" in line


def test_unknown_body_field_is_422(client):
    """An unknown JSON field is refused, naming it."""
    response = client.post("/v1/render", json={"preset": "sphere", "colour": "red"})
    assert response.status_code == 422
    assert any(line.startswith("colour") for line in problems(response))


def test_bad_choice_and_bad_json_are_422(client):
    """A value outside a choice, invalid JSON and a missing body each answer 422 with one line."""
    assert "format" in problems(client.get("/v1/render?format=jpg"))[0]
    bad = client.post("/v1/render", content=b"{", headers={"content-type": "application/json"})
    assert bad.status_code == 400 and "JSON" in problems(bad)[0]
    empty = client.post("/v1/render", content=b"", headers={"content-type": "application/json"})
    assert empty.status_code == 400 and "JSON object is required" in problems(empty)[0]


@pytest.mark.parametrize("path", ["/v1/render", "/v1/export/glb", "/v1/turntables"])
def test_a_body_not_sent_as_json_is_415(client, path):
    """`curl -d` labels a body a form: refused as such, naming the header to send, where it
    was read as JSON whatever it was labelled; JSON's own types and no label are read."""
    body = b'{"preset": "sphere", "frames": 2}' if "turntables" in path else b'{"preset": "sphere"}'
    for label in ("application/x-www-form-urlencoded", "text/plain; charset=utf-8"):
        refused = client.post(path, content=body, headers={"content-type": label})
        assert refused.status_code == 415, refused.text
        assert refused.json()["error"] == "unsupported_media_type"
        assert "application/json" in problems(refused)[0]
    if "turntables" in path:
        return  # accepted ones would start a turntable: the render route shows the rest
    for label in ("application/json; charset=utf-8", "application/problem+json", None):
        headers = {"content-type": label} if label else {}
        answer = client.post(path, content=body, headers=headers)
        assert answer.status_code == 200, (label, answer.text)


def test_mdf_bad_input_is_422(client):
    """The MDF route checks its own fields: size, format and wavelengths."""
    lines = problems(client.get("/v1/mdf?size=4096&format=png16&wavelengths=200&bogus=1"))
    for name in ("size=", "format=", "wavelengths=", "bogus"):
        assert any(line.startswith(name) for line in lines), lines
    assert any(line.startswith("size=") and "[16 … 2048]" in line for line in lines)
    assert any(line.startswith("bogus") and "size" in line for line in lines)


def test_unknown_preset_is_404_listing_presets(client):
    """An unknown preset answers 404 whose message lists the valid names."""
    for response in (client.get("/v1/render?preset=teapot"), client.get("/v1/presets/teapot"),
                     client.post("/v1/render", json={"preset": "teapot"})):
        assert response.status_code == 404
        (line,) = problems(response)
        assert "teapot" in line and "cd-rom" in line and response.json()["error"] == "unknown_preset"


def test_cost_over_budget_is_422_naming_the_budget(backend):
    """A request over the cost budget answers 422 whose message names the budget."""
    draft = TIERS["draft"]
    budget = 64 * 64 * draft.samples * max(draft.wavelengths, 3)  # one draft 64² image
    with make_client(backend, cost_budget=budget) as client:
        assert client.get(f"/v1/render?{SMALL}").status_code == 200
        response = client.get("/v1/render?width=128&height=64&quality=draft")
        assert response.status_code == 422
        assert f"budget of {budget}" in problems(response)[0]
        assert client.get("/v1/mdf?size=128").status_code == 422


def test_size_over_service_limit_is_422(backend):
    """A size within the parameter range but over the service's max_width answers 422."""
    with make_client(backend, max_width=128, max_height=96) as client:
        lines = problems(client.get("/v1/render?width=256&height=256"))
        assert any(line.startswith("width=256") and "128" in line for line in lines)
        assert any(line.startswith("height=256") and "96" in line for line in lines)
        fields = client.get("/v1/render?width=256&height=256").json()["fields"]
        assert [(f["field"], f["message"]) for f in fields] == list(zip(("width", "height"),
                                                                         lines, strict=True))
        assert client.get("/v1/mdf?size=200").status_code == 422


def test_service_limits_are_within_the_parameter_ranges():
    """MAX_PIXELS and the "[16 … limit]" of a limit message are the size fields' own range."""
    assert field_range(RenderFields, "width") == f"[16 … {MAX_PIXELS}]"


def test_body_over_limit_is_413(backend):
    """A body over max_body_bytes answers 413, by Content-Length or counted while streaming."""
    with make_client(backend, max_body_bytes=1024) as client:
        padded = b'{"preset": "sphere"' + b" " * 2000 + b"}"
        response = client.post("/v1/render", content=padded,
                               headers={"content-type": "application/json"})
        assert response.status_code == 413

        def chunks():
            yield padded[:600]
            yield padded[600:]

        streamed = client.post("/v1/render", content=chunks(),
                               headers={"content-type": "application/json"})
        assert streamed.status_code == 413
        assert sample(client, "opaline_rejected_requests_total", {"reason": "too_large"}) == 2


def test_settings_come_from_env_and_dependency_overrides(backend, monkeypatch):
    """OPALINE_* variables set the settings; overriding get_settings changes what routes use."""
    monkeypatch.setenv("OPALINE_MAX_WIDTH", "100")
    monkeypatch.setenv("OPALINE_GL_BACKEND", backend.upper())
    assert Settings().max_width == 100 and Settings().gl_backend == backend
    monkeypatch.delenv("OPALINE_MAX_WIDTH")
    with make_client(backend) as client:
        assert client.get("/v1/render?width=128&height=64&quality=draft").status_code == 200
        client.app.dependency_overrides[get_settings] = lambda: Settings(max_width=100)
        assert client.get("/v1/render?width=128&height=64&quality=draft").status_code == 422


# Load and failure


def test_full_queue_is_503_with_retry_after(backend, tmp_path):
    """With the worker busy and the queue full, a new render answers 503 with Retry-After."""
    with make_client(backend, queue_size=1) as client:
        gate = occupy(client, tmp_path)
        client.app.state.pool.submit("queued", EchoTask())
        response = client.get(f"/v1/render?{SMALL}&mu_f=1.25")
        gate.open()
        assert response.status_code == 503 and response.headers["retry-after"] == "1"
        assert sample(client, "opaline_rejected_requests_total", {"reason": "queue_full"}) == 1
        end = time.monotonic() + WAIT
        while client.app.state.pool.depth() and time.monotonic() < end:  # the queue drains
            time.sleep(0.01)
        assert client.get(f"/v1/render?{SMALL}&mu_f=1.25").status_code == 200


def test_request_past_deadline_is_503(backend, tmp_path):
    """A request that waited in the queue past deadline_s is dropped and answers 503."""
    with make_client(backend, deadline_s=0.3) as client:
        # The variant rendered once (mu_f is a uniform): admission no longer adds its compile.
        assert client.get(f"/v1/render?{SMALL}&mu_f=1.5").status_code == 200
        gate = occupy(client, tmp_path)
        answers: list = []
        asker = threading.Thread(
            target=lambda: answers.append(client.get(f"/v1/render?{SMALL}&mu_f=1.75")))
        asker.start()
        time.sleep(0.6)
        gate.open()
        asker.join(WAIT)
        assert answers[0].status_code == 503 and "Retry-After" in answers[0].headers
        assert sample(client, "opaline_rejected_requests_total", {"reason": "deadline"}) == 1
        assert sample(client, "opaline_render_seconds_count", {"preset": "sphere"}) == 1


def test_identical_concurrent_requests_render_once(backend, tmp_path):
    """N identical concurrent requests get the same image from a single render."""
    count = 6
    with make_client(backend) as client:
        gate = occupy(client, tmp_path)
        url = f"/v1/render?preset=perturbed-cube&{SMALL}"
        answers: list = []
        askers = [threading.Thread(target=lambda: answers.append(client.get(url)))
                  for _ in range(count)]
        for asker in askers:
            asker.start()
        end = time.monotonic() + WAIT
        while sample(client, "opaline_cache_misses_total") < count and time.monotonic() < end:
            time.sleep(0.01)
        gate.open()
        for asker in askers:
            asker.join(WAIT)
        assert [a.status_code for a in answers] == [200] * count
        assert len({a.content for a in answers}) == 1
        renders = sample(client, "opaline_render_seconds_count", {"preset": "perturbed-cube"})
        assert renders == 1


def test_render_failure_is_500_without_the_log(backend, caplog):
    """A shader failure answers 500 with an incident id; the compile log stays in the server log."""
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=False),
                     renderer_factory=partial(BrokenRenderer, backend))
    with caplog.at_level(logging.ERROR), TestClient(app) as client:
        response = client.get(f"/v1/render?{SMALL}")
        assert response.status_code == 500
        assert "incident" in problems(response)[0]
        assert "SECRET" not in response.text
        assert client.get("/healthz").status_code == 200
        assert scraped(client, "opaline_render_failures_total") == 1
        assert scraped(client, "opaline_context_restarts_total") == 0  # a shader error spares it
    assert "SECRET-COMPILE-LOG" in caplog.text


def test_a_lost_context_is_counted_and_made_anew(backend):
    """A render that raises past the shader (a lost context) answers 500, counts as a render
    failure, and its worker's context is made anew, counted on /metrics, before it is ready."""
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=False),
                     renderer_factory=partial(LostContextRenderer, backend))
    with TestClient(app) as client:
        assert scraped(client, "opaline_context_restarts_total") == 0
        assert client.get(f"/v1/render?{SMALL}").status_code == 500
        assert scraped(client, "opaline_render_failures_total") == 1
        end = time.monotonic() + WAIT
        while scraped(client, "opaline_context_restarts_total") < 1 and time.monotonic() < end:
            time.sleep(0.05)
        assert scraped(client, "opaline_context_restarts_total") == 1
        assert client.get("/readyz").json()["workers"][0]["restarts"] == 1


def test_shutdown_releases_the_workers(backend):
    """Leaving the lifespan stops every worker (each releases its context on its own thread)."""
    client = make_client(backend, workers=2)
    with client:
        assert client.get("/readyz").status_code == 200
    assert [w["state"] for w in client.app.state.pool.status()] == ["stopped", "stopped"]


# OpenAPI


def test_openapi_documents_every_parameter_and_media_type(client):
    """/docs' schema gives each image parameter a description, numeric ones their bounds."""
    spec = client.get("/openapi.json").json()
    params = spec["paths"]["/v1/render"]["get"]["parameters"]
    for param in params:
        assert param["description"], param["name"]
    bounded = {p["name"]: p["schema"]["anyOf"][0] for p in params if p["name"] in ("mu_f", "width")}
    assert bounded["mu_f"]["maximum"] == 1000 and bounded["width"]["minimum"] == 16
    for path, method in (("/v1/render", "get"), ("/v1/render", "post"), ("/v1/mdf", "get")):
        content = spec["paths"][path][method]["responses"]["200"]["content"]
        assert {"image/png", "application/x-npy"} <= set(content)
    assert "Retry-After" in spec["paths"]["/v1/render"]["get"]["responses"]["503"]["headers"]
    assert client.get("/docs").status_code == 200


def test_openapi_documents_readiness_etag_and_mdf_bounds(client):
    """/readyz's body is described for 200 and 503; images document their ETag; mdf its bounds."""
    spec = client.get("/openapi.json").json()
    ready = spec["paths"]["/readyz"]["get"]["responses"]
    for status in ("200", "503"):
        assert ready[status]["content"]["application/json"]["schema"]["$ref"].endswith("Readiness")
    for path, method in (("/v1/render", "get"), ("/v1/render", "post"), ("/v1/mdf", "get")):
        assert "ETag" in spec["paths"][path][method]["responses"]["200"]["headers"]
    mdf = {p["name"]: p["schema"] for p in spec["paths"]["/v1/mdf"]["get"]["parameters"]}
    assert mdf["wavelengths"]["minimum"] == 0 and mdf["wavelengths"]["maximum"] == 128


def test_openapi_says_what_each_health_route_means(client):
    """/healthz is documented as liveness, /readyz as readiness with per-worker detail."""
    paths = client.get("/openapi.json").json()["paths"]
    health, ready = paths["/healthz"]["get"], paths["/readyz"]["get"]
    assert "liveness" in health["summary"].lower() and "/readyz" in health["description"]
    assert "readiness" in ready["summary"].lower() and "503" in ready["description"]
    workers = client.get("/readyz").json()["workers"][0]
    assert {"pid", "state", "renders", "rss_bytes", "restarts"} <= workers.keys()


def test_container_health_check_asks_readiness():
    """The image is unhealthy when no worker can render: its HEALTHCHECK asks /readyz."""
    dockerfile = (Path(__file__).resolve().parents[2] / "Dockerfile").read_text()
    check = dockerfile[dockerfile.index("HEALTHCHECK"):]
    assert "/readyz" in check.split("\n\n")[0] and "/healthz" not in check.split("\n\n")[0]


def test_not_ready_until_the_start_up_calibration_is_done(backend):
    """While the start-up calibration runs, admission counts it as work ahead, so /readyz is
    503 until it is done (then 200, and renders are admitted)."""
    app = create_app(Settings(gl_backend=backend, warmup=False, calibrate=True))
    with TestClient(app) as client:
        first = client.get("/readyz")
        assert first.status_code == 503 and first.json()["calibrated"] is False
        end = time.monotonic() + 120
        while client.get("/readyz").status_code != 200:
            assert time.monotonic() < end, "never ready"
            time.sleep(0.1)
        assert client.get("/readyz").json()["calibrated"] is True
        assert client.get(f"/v1/render?{SMALL}&mu_f=2.5").status_code == 200


def test_quality_auto_says_what_it_picked(client):
    """A render with an error budget answers with the setting quality=auto chose and why."""
    answer = client.get("/v1/render?preset=cd-rom&width=128&height=128&max_flip=0.05")
    assert answer.status_code == 200
    assert answer.headers["X-Opaline-Auto-Target"] == "max_flip=0.05"
    assert "samples=" in answer.headers["X-Opaline-Auto-Setting"]
    assert "X-Opaline-Auto-Target" not in client.get(f"/v1/render?{SMALL}").headers


def test_web_modules_are_served_as_javascript_under_the_page_csp():
    """The page's ES modules come from /static with a JavaScript type (a module of any other
    type is refused under nosniff), each import names a module of the folder, and index.html
    loads them with no inline script, which its CSP (script-src 'self') would refuse."""
    app = FastAPI()
    app.add_middleware(SecurityHeaders)
    mount_web(app)
    modules = sorted(WEB_DIR.glob("*.js"))
    assert {p.name for p in modules} >= {"main.js", "api.js", "schema.js", "assets.js"}
    with TestClient(app) as client:
        page = client.get("/")
        assert "script-src 'self'" in page.headers["content-security-policy"]
        assert '<script type="module" src="/static/main.js"></script>' in page.text
        assert "<script>" not in page.text
        for path in modules:
            answer = client.get(f"/static/{path.name}")
            assert answer.status_code == 200, path.name
            assert answer.headers["content-type"].split(";")[0] in (
                "text/javascript", "application/javascript"), answer.headers
            for name in re.findall(r"from '\./([\w-]+\.js)'", answer.text):
                assert (WEB_DIR / name).is_file(), (path.name, name)
