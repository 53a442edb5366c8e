"""The HTTP client and `opaline batch --server`, against a fake Opaline on 127.0.0.1."""

from __future__ import annotations

import hashlib
import io
import json
import socket
import threading
import time
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, HTTPServer, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qsl, urlsplit

import numpy as np
import pytest
from PIL import Image
from pydantic import ValidationError

from opaline.batch.client import NAMING, RemoteError, RemoteRenderer
from opaline.cli.main import main
from opaline.model.params import RenderRequest, describe_errors
from opaline.model.presets import UnknownPreset, get_preset
from opaline.pipeline.prepare import prepare
from opaline.server.canonical import CanonicalQuery

SMALL = {"width": 64, "height": 64, "quality": "draft"}


def canned_png(body: dict) -> bytes:
    """A flat PNG of the requested size whose colour depends on the whole request."""
    digest = hashlib.sha256(json.dumps(body, sort_keys=True).encode()).digest()
    image = Image.new("RGB", (body.get("width", 256), body.get("height", 256)), tuple(digest[:3]))
    out = io.BytesIO()
    image.save(out, format="PNG")
    return out.getvalue()


class FakeOpaline:
    """What the fake server saw and how it misbehaves: 503 for the first ``busy`` requests."""

    def __init__(self, busy: int = 0, render=canned_png, delay: float = 0.0) -> None:
        self.busy = busy
        self.render = render
        self.delay = delay
        self.bodies: list[dict] = []
        self.asked: list[str] = []  # "GET /v1/render?…" or "POST /v1/render"
        self.statuses: list[int] = []
        self.in_flight = self.max_in_flight = 0
        self.lock = threading.Lock()

    def answer(self, body: dict) -> tuple[int, dict[str, str], bytes]:
        with self.lock:
            self.bodies.append(body)
            if self.busy > 0:
                self.busy -= 1
                return 503, {"Retry-After": "0"}, b'{"detail": "queue full; retry later"}'
        try:
            RenderRequest.model_validate(body)
            get_preset(body.get("preset", "sphere"))
        except ValidationError as exc:
            return 422, {}, json.dumps({"detail": describe_errors(exc)}).encode()
        except UnknownPreset as exc:
            return 404, {}, json.dumps({"detail": str(exc)}).encode()
        return 200, {"Content-Type": "image/png"}, self.render(body)


def handler_for(fake: FakeOpaline) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 (http.server's naming)
            query = CanonicalQuery.model_validate(dict(parse_qsl(urlsplit(self.path).query)))
            self.answer(query.request().model_dump(mode="json", exclude_none=True))

        def do_POST(self) -> None:  # noqa: N802
            self.answer(json.loads(self.rfile.read(int(self.headers["Content-Length"]))))

        def answer(self, body: dict) -> None:
            with fake.lock:
                fake.in_flight += 1
                fake.max_in_flight = max(fake.max_in_flight, fake.in_flight)
                fake.asked.append(f"{self.command} {self.path}")
            try:
                time.sleep(fake.delay)
                if urlsplit(self.path).path != "/v1/render":
                    status, headers, data = 404, {}, b'{"detail": "not found"}'
                else:
                    status, headers, data = fake.answer(body)
            finally:
                with fake.lock:
                    fake.in_flight -= 1
                    fake.statuses.append(status)
            self.send_response(status)
            headers.setdefault("Content-Type", "application/json")
            for key, value in {**headers, "Content-Length": str(len(data))}.items():
                self.send_header(key, value)
            self.end_headers()
            self.wfile.write(data)

        def log_message(self, *args: object) -> None:
            pass

    return Handler


@contextmanager
def serving(fake: FakeOpaline, threaded: bool = True):
    """The fake on an ephemeral 127.0.0.1 port; yields its URL."""
    server_class = ThreadingHTTPServer if threaded else HTTPServer
    server = server_class(("127.0.0.1", 0), handler_for(fake))
    thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.05},
                              daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


def closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def request(**fields) -> RenderRequest:
    return RenderRequest(**{**SMALL, **fields})


def test_a_request_is_asked_at_its_canonical_url_and_a_dict_posted_as_is():
    """A RenderRequest is a GET of the URL the service names in Content-Location (what a
    shared cache keeps); a dict, or a request naming a mesh, is POSTed unchanged."""
    fake = FakeOpaline()
    asked = request(preset="cd-rom", mu_f=6, albedo=(0.1, 0.2, 0.3))
    meshed = request(preset="cd-rom", mesh="0" * 32)
    with serving(fake) as url, RemoteRenderer(url) as remote:
        data = remote.render(asked)
        remote.render(asked.model_dump(mode="json", exclude_none=True))
        remote.render(meshed)
    assert fake.asked == [f"GET {prepare(asked, NAMING).url()}", "POST /v1/render",
                          "POST /v1/render"]
    assert fake.bodies[0] == CanonicalQuery.model_validate(
        dict(parse_qsl(urlsplit(fake.asked[0]).query))).request().model_dump(
            mode="json", exclude_none=True)
    assert fake.bodies[1] == asked.model_dump(mode="json", exclude_none=True)
    assert fake.bodies[2] == meshed.model_dump(mode="json", exclude_none=True)
    assert data == canned_png(fake.bodies[0])


def test_503_is_retried_until_the_server_answers():
    """Three 503s with Retry-After, then the image: four attempts, the bytes returned."""
    fake = FakeOpaline(busy=3)
    with serving(fake) as url, RemoteRenderer(url, backoff=0.01) as remote:
        data = remote.render(request(preset="cd-rom"))
        assert remote.attempts == 4
    assert fake.statuses == [503, 503, 503, 200]
    with Image.open(io.BytesIO(data)) as image:
        assert image.size == (64, 64)


def test_retries_are_bounded():
    """A server that stays busy gives a RemoteError after retries + 1 attempts, not a hang."""
    fake = FakeOpaline(busy=100)
    with serving(fake) as url, RemoteRenderer(url, retries=2, backoff=0.01) as remote:
        with pytest.raises(RemoteError, match=r"HTTP 503: queue full.*\(after 3") as info:
            remote.render(request())
    assert info.value.status == 503 and len(fake.bodies) == 3


def test_422_detail_list_is_reported_and_not_retried():
    """A 4xx is final: one attempt, and the server's lines (field, value, range) in the error."""
    fake = FakeOpaline()
    body = {"preset": "cd-rom", "mu_f": 5000}  # a dict is sent as is, unvalidated
    with serving(fake) as url, RemoteRenderer(url, backoff=0.01) as remote:
        with pytest.raises(RemoteError) as info:
            remote.render(body)
        assert remote.attempts == 1
    assert info.value.status == 422
    assert "mu_f=5000 is out of range: allowed [0 … 1000]" in str(info.value)


def test_404_detail_string_is_reported():
    """A string detail (unknown preset) becomes the error message."""
    fake = FakeOpaline()
    with serving(fake) as url, RemoteRenderer(url) as remote:
        with pytest.raises(RemoteError, match="HTTP 404: preset='nope' is not known") as info:
            remote.render({"preset": "nope"})
    assert info.value.status == 404


def test_connection_errors_are_retried_then_reported():
    """Nobody listening: the client retries with backoff, then fails with the transport error."""
    url = f"http://127.0.0.1:{closed_port()}"
    with RemoteRenderer(url, retries=2, backoff=0.01) as remote:
        started = time.monotonic()
        with pytest.raises(RemoteError, match="ConnectError.*after 3 attempts") as info:
            remote.render(request())
        assert remote.attempts == 3 and info.value.status is None
    assert time.monotonic() - started < 5


def test_backoff_honours_retry_after_and_is_capped():
    """Retry-After is used when given (capped); otherwise the delay doubles, jittered, capped."""
    remote = RemoteRenderer("http://127.0.0.1:1", backoff=0.5, max_delay=4.0)
    try:
        assert remote.delay(0, "2") == 2.0
        assert remote.delay(0, "100") == 4.0
        assert 0.25 <= remote.delay(0) <= 0.5
        assert 1.0 <= remote.delay(2) <= 2.0
        assert 2.0 <= remote.delay(10) <= 4.0
        assert 0.25 <= remote.delay(0, "Wed, 21 Oct 2015 07:28:00 GMT") <= 0.5
    finally:
        remote.close()


def write_materials(folder: Path, count: int) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for i in range(count):
        fields = {"preset": "cd-rom", "mu_f": i + 1, **SMALL, "width": 32 + 8 * i}
        (folder / f"disc-{i}.json").write_text(json.dumps(fields))
    (folder / "hot.json").write_text(json.dumps({"preset": "cd-rom", "mu_f": -1}))


def run_cli(*args: str) -> int:
    try:
        return main(list(args))
    except SystemExit as exc:
        return int(exc.code or 0)


def test_batch_through_server_retries_503_and_bounds_concurrency(tmp_path):
    """--server renders every valid file remotely through 503s, at most --jobs at once."""
    folder, out = tmp_path / "m", tmp_path / "out"
    write_materials(folder, 6)
    fake = FakeOpaline(busy=4, delay=0.05)
    with serving(fake) as url:
        status = run_cli("batch", str(folder), "--out", str(out), "--server", url, "--jobs", "2")
    assert status == 1, "the invalid file fails the run"
    assert 1 <= fake.max_in_flight <= 2
    assert fake.statuses.count(503) == 4 and fake.statuses.count(200) == 6
    summary = json.loads((out / "summary.json").read_text())
    items = {item["name"]: item for item in summary["items"]}
    assert summary["server"] == url and summary["counts"]["rendered"] == 6
    assert "mu_f=-1 is out of range" in items["hot"]["error"], "validated locally"
    assert len(fake.bodies) == 10, "the invalid file never reached the server"
    for i in range(6):
        with Image.open(out / f"disc-{i}.png") as image:
            assert image.size == (32 + 8 * i, 64)
    assert run_cli("batch", str(folder), "--out", str(out), "--server", url) == 1
    again = json.loads((out / "summary.json").read_text())["counts"]
    assert again == {"rendered": 0, "skipped": 6, "failed": 1}, "up to date, no request sent"


def test_batch_reports_server_errors_per_item(tmp_path):
    """An item the server refuses fails with the server's message; the others still render."""
    folder, out = tmp_path / "m", tmp_path / "out"
    write_materials(folder, 2)
    fake = FakeOpaline()
    refusing = FakeOpaline.answer

    def answer(self, body):
        if body.get("mu_f") == 2:
            return 422, {}, json.dumps({"detail": ["mu_f=2: refused by this server"]}).encode()
        return refusing(self, body)

    fake.answer = answer.__get__(fake)
    with serving(fake) as url:
        assert run_cli("batch", str(folder), "--out", str(out), "--server", url) == 1
    items = {i["name"]: i for i in json.loads((out / "summary.json").read_text())["items"]}
    assert items["disc-0"]["status"] == "rendered"
    assert "HTTP 422: mu_f=2: refused by this server" in items["disc-1"]["error"]


@pytest.mark.gl
def test_remote_images_equal_local_ones(tmp_path, backend):
    """A server that really renders (LocalRenderer) gives the same bytes as a local batch."""
    from opaline.local import api as api_python

    folder = tmp_path / "m"
    write_materials(folder, 3)
    (folder / "hot.json").unlink()

    def render(body: dict) -> bytes:
        return api_python.render(body, backend=backend)  # on the server's one thread

    fake = FakeOpaline(busy=1, render=render)
    with serving(fake, threaded=False) as url:
        assert run_cli("batch", str(folder), "--out", str(tmp_path / "remote"),
                       "--server", url) == 0
        # The server thread's context is not released: it lives until this process exits.
    assert run_cli("batch", str(folder), "--out", str(tmp_path / "local"),
                   "--backend", backend) == 0
    for i in range(3):
        remote = (tmp_path / "remote" / f"disc-{i}.png").read_bytes()
        local = (tmp_path / "local" / f"disc-{i}.png").read_bytes()
        assert remote == local
        with Image.open(io.BytesIO(remote)) as image:
            assert np.asarray(image).std() > 1


def test_negative_retries_are_refused():
    """retries counts the attempts after the first: below zero is an error, not zero attempts."""
    with pytest.raises(ValueError, match="retries=-1"):
        RemoteRenderer("http://127.0.0.1:1", retries=-1)
