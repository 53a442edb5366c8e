"""One cacheable URL per image: canonical GET URLs, Content-Location, immutable, ETags."""

from __future__ import annotations

from urllib.parse import parse_qsl, urlsplit

import pytest
from fastapi.testclient import TestClient
from hypothesis import example, given
from hypothesis import strategies as st

from opaline.model.params import RenderRequest
from opaline.model.presets import all_presets, get_preset
from opaline.model.request import resolve
from opaline.pipeline.canonical import spell
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, prepare
from opaline.server.api import create_app
from opaline.server.cache import etag
from opaline.server.canonical import IMMUTABLE, CanonicalQuery
from opaline.settings import Settings

PRESETS_ONLY = Context(Limits(cost_budget=None), meshes=lambda request, preset: preset)


def url_of(**fields) -> str:
    return prepare(RenderRequest(**fields), PRESETS_ONLY).url()


def parse(url: str) -> RenderRequest:
    """What a canonical URL asks for, read back as GET /v1/render reads its query."""
    pairs = parse_qsl(urlsplit(url).query)
    return CanonicalQuery.model_validate(dict(pairs)).request()


def test_spellings_of_one_request_share_one_url():
    """Field order, defaults stated or not, and float spelling do not change the URL."""
    one = url_of(preset="cd-rom", mu_f=8, exposure=1.0, width=64, quality="standard")
    two = url_of(width=64, mu_f=8.000, preset="cd-rom")
    assert one == two
    assert url_of(preset="cd-rom", mu_f=8.5) != url_of(preset="cd-rom", mu_f=8.25)


def test_defaults_are_dropped_and_order_is_fixed():
    """Only what differs from the preset (and its tier) stays; preset and quality lead, rev ends."""
    assert url_of().startswith("/v1/render?rev=")
    url = url_of(height=80, preset="oil-slick", albedo=(0.1, 0.2, 0.3), quality="high",
                 samples=8)  # 8 is the high tier's own: dropped
    names = [name for name, _ in parse_qsl(urlsplit(url).query)]
    assert names == ["preset", "quality", "albedo", "height", "rev"]
    assert "albedo=0.1,0.2,0.3" in url


def test_floats_have_one_spelling():
    assert [spell(v) for v in (1.0, 1e0, 0.1, 2.5e-7, 1e6, (0.5, 1.0, 0.0))] == [
        "1", "1", "0.1", "2.5e-07", "1000000", "0.5,1,0"]


FIELD_VALUES = st.fixed_dictionaries({}, optional={
    "preset": st.sampled_from(sorted(all_presets())),
    "quality": st.sampled_from(["draft", "standard", "high", "reference", "auto"]),
    "samples": st.integers(1, 64), "wavelengths": st.sampled_from([0, 4, 16, 32]),
    "width": st.integers(16, 512), "mu_f": st.floats(0, 1000), "theta1": st.floats(-6, 6),
    "exposure": st.floats(0.01, 1000), "aa": st.sampled_from(["none", "analytic"]),
    "albedo": st.tuples(*[st.floats(0, 1)] * 3), "light_azimuth": st.floats(-360, 360),
    "camera_elevation": st.floats(-89, 89),
    "environment": st.sampled_from(["studio", "neutral", "sky"]),
    "environment_background": st.booleans(), "environment_blur": st.floats(0, 1),
    "max_flip": st.floats(0.001, 1.0), "transparent": st.booleans()})


@given(FIELD_VALUES)
@example({"theta1": -0.0})  # -0.0 == 0.0 but JSON (so the key) spells them apart
def test_canonical_url_reads_back_as_the_same_image(fields):
    """Whatever the request, its canonical URL resolves to the same job, and is its own
    canonical URL (same rev)."""
    if "max_flip" in fields and fields.get("quality", "auto") != "auto":
        del fields["max_flip"]  # a budget chooses the tier: refused with one named
    request = RenderRequest(**fields)
    preset = get_preset(request.preset)
    url = url_of(**fields)
    again = parse(url)
    assert resolve(again, preset) == resolve(request, preset)
    assert url_of(**again.model_dump(exclude_none=True)) == url


@pytest.mark.gl
def test_every_answer_names_the_canonical_url(backend):
    """POST and a hand-spelled GET give Content-Location; GET there gives the same bytes and
    strong ETag, immutable; If-None-Match with it is 304."""
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False)
    with TestClient(create_app(settings)) as client:
        body = {"preset": "cd-rom", "width": 48, "height": 48, "quality": "draft", "mu_f": 3.0}
        posted = client.post("/v1/render", json=body)
        location = posted.headers["content-location"]
        assert location == url_of(**body)
        spelled = client.get("/v1/render?quality=draft&mu_f=3.00&height=48&width=48"
                             "&preset=cd-rom")
        assert spelled.headers["content-location"] == location
        assert "immutable" not in spelled.headers["cache-control"]
        got = client.get(location)
        assert got.status_code == 200 and got.headers["cache-control"] == IMMUTABLE
        assert got.content == posted.content == spelled.content
        assert got.headers["etag"] == posted.headers["etag"] == etag(got.content)
        again = client.get(location, headers={"If-None-Match": got.headers["etag"]})
        assert again.status_code == 304 and again.headers["cache-control"] == IMMUTABLE
        stale = client.get(location[:-32] + "0" * 32)  # rev is last: another content key
        assert stale.status_code == 200 and "immutable" not in stale.headers["cache-control"]
        assert stale.headers["content-location"] == location


@pytest.mark.gl
def test_mdf_plots_have_canonical_urls_too(backend):
    """GET /v1/mdf names its canonical URL; there it is immutable, with the same bytes."""
    settings = Settings(gl_backend=backend, warmup=False, calibrate=False)
    with TestClient(create_app(settings)) as client:
        spelled = client.get("/v1/mdf?size=32&alpha=1.50&mu_f=5&format=png&mdf=multipeak")
        location = spelled.headers["content-location"]
        assert location.startswith("/v1/mdf?mu_f=5&alpha=1.5&size=32&rev=")
        assert "immutable" not in spelled.headers["cache-control"]
        got = client.get(location)
        assert got.headers["cache-control"] == IMMUTABLE and got.content == spelled.content
        assert got.headers["content-location"] == location
