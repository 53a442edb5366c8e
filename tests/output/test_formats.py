"""WebP, AVIF and JPEG output, format=auto from the Accept header, and Server-Timing."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from fastapi.testclient import TestClient
from PIL import Image

from opaline.model.params import RenderRequest
from opaline.output import encode
from opaline.output.formats import negotiate
from opaline.server.api import create_app
from opaline.settings import Settings

CHROME = "image/avif,image/webp,image/apng,image/svg+xml,image/*,*/*;q=0.8"


def photo(alpha: bool, seed: int = 0) -> np.ndarray:
    """A smooth image with some texture: what lossy codecs are meant for."""
    y, x = np.mgrid[0:48, 0:64] / 64.0
    rng = np.random.default_rng(seed)
    channels = [np.sin(6 * x + 2 * y), np.cos(5 * y - x), x * y, np.ones_like(x) * 0.8][:4 if alpha else 3]
    image = np.stack(channels, -1) * 0.4 + 0.5 + rng.normal(0, 0.01, (48, 64, len(channels)))
    return encode.quantise(image, 8)


ROUND_TRIPS = [("webp-lossless", "WEBP", 0.0), ("webp", "WEBP", 4.0), ("avif", "AVIF", 4.0),
               ("jpeg", "JPEG", 3.0)]


@pytest.mark.parametrize("fmt,mime,tolerance,alpha",
                         [(*case, alpha) for case in ROUND_TRIPS for alpha in (False, True)
                          if not (case[0] == "jpeg" and alpha)])  # JPEG has no alpha
def test_formats_round_trip(fmt, mime, tolerance, alpha):
    """Each format decodes to the size, mode and (within its loss) the pixels written."""
    pixels = photo(alpha)
    data = encode.encode_frame(type("F", (), {"pixels": pixels})(), fmt, alpha)
    image = Image.open(io.BytesIO(data))
    assert image.format == mime and image.size == (64, 48)
    back = np.asarray(image.convert("RGBA" if alpha else "RGB")).astype(float)
    error = np.abs(back - pixels).mean()
    assert error <= tolerance, error
    if tolerance == 0.0:
        assert np.array_equal(back, pixels)


@pytest.mark.parametrize("fmt", ["png", "webp", "webp-lossless", "avif", "jpeg"])
def test_same_pixels_same_bytes(fmt):
    pixels = photo(False, seed=3)
    frame = type("F", (), {"pixels": pixels})()
    assert encode.encode_frame(frame, fmt) == encode.encode_frame(frame, fmt)


def test_png_of_pixels_round_trips_exactly_with_up_filter():
    """The hand-built 8-bit PNG (filter 'up', wrapping differences) decodes exactly."""
    for alpha in (False, True):
        pixels = np.random.default_rng(4).integers(0, 256, (21, 13, 4 if alpha else 3), np.uint8)
        back = np.asarray(Image.open(io.BytesIO(encode.png_pixels(pixels))))
        assert np.array_equal(back, pixels)


@pytest.mark.parametrize("accept,alpha,expected", [
    (CHROME, False, "webp"),
    ("image/avif", False, "avif"),
    ("image/jpeg", False, "jpeg"),
    ("image/jpeg", True, None),  # JPEG cannot carry alpha
    ("image/jpeg, image/png;q=0.9", True, "png"),
    ("image/webp;q=0.5, image/png", False, "png"),  # q wins over the service's order
    ("image/webp;q=0, image/*", False, "png"),  # q=0 refuses
    ("*/*", False, "png"), ("image/*", False, "png"), (None, False, "png"), ("", False, "png"),
    ("text/html", False, None),
])
def test_negotiation(accept, alpha, expected):
    assert negotiate(accept, alpha) == expected


def test_auto_is_png_outside_http():
    from opaline.model.request import resolve

    assert resolve(RenderRequest(format="auto")).format == "png"


@pytest.fixture(scope="module")
def client(backend):
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False, workers=1)
    with TestClient(create_app(settings)) as client:
        yield client


QUERY = "/v1/render?width=32&height=32&quality=draft"


@pytest.mark.gl
def test_auto_negotiates_with_vary_and_a_tag_per_format(client):
    answers = {}
    for accept, mime in ((CHROME, "image/webp"), ("image/avif", "image/avif"),
                         ("image/png", "image/png"), ("image/jpeg", "image/jpeg")):
        answer = client.get(QUERY + "&format=auto", headers={"Accept": accept})
        assert answer.status_code == 200, answer.text
        assert answer.headers["content-type"] == mime
        assert answer.headers["vary"] == "Accept"
        answers[mime] = answer
        Image.open(io.BytesIO(answer.content)).load()
    tags = {a.headers["etag"] for a in answers.values()}
    assert len(tags) == 4
    # A named format is the same image as the one negotiated, and does not vary.
    named = client.get(QUERY + "&format=webp")
    assert named.headers["etag"] == answers["image/webp"].headers["etag"]
    assert "vary" not in named.headers
    again = client.get(QUERY + "&format=auto", headers={
        "Accept": "image/avif", "If-None-Match": answers["image/avif"].headers["etag"]})
    assert again.status_code == 304


@pytest.mark.gl
def test_auto_refuses_what_it_cannot_make(client):
    assert client.get(QUERY + "&format=auto", headers={"Accept": "text/html"}).status_code == 406
    answer = client.get(QUERY + "&format=jpeg&transparent=true")
    assert answer.status_code == 422 and "alpha" in answer.text
    # Transparency, not the Accept header, is what rules JPEG out: the 406 says so (it said
    # the header allowed none of the four, image/jpeg among them).
    only_jpeg = client.get(QUERY + "&format=auto&transparent=true",
                           headers={"Accept": "image/jpeg"})
    assert only_jpeg.status_code == 406
    assert "no alpha channel" in only_jpeg.json()["detail"][0], only_jpeg.text


@pytest.mark.gl
def test_server_timing_says_hit_or_miss(client):
    query = QUERY + "&format=png&exposure=1.25"
    miss, hit = client.get(query), client.get(query)
    timing = re.compile(r'^(hit|miss);desc="\w+"(, render;dur=[\d.]+)?, total;dur=[\d.]+$')
    assert timing.match(miss.headers["server-timing"]).group(1) == "miss"
    assert "render;dur=" in miss.headers["server-timing"]
    assert timing.match(hit.headers["server-timing"]).group(1) == "hit"
    assert "render" not in hit.headers["server-timing"]
