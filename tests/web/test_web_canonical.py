"""The page asks for its previews at the service's canonical URLs (canonical.js), so a
shared cache in front of the replicas keys them as every other client does."""

from __future__ import annotations

from urllib.parse import urlsplit

import pytest

from opaline.batch.client import canonical_path
from opaline.model.params import RenderRequest
from opaline.model.tiers import TIERS
from test_web import (  # noqa: F401
    CHROMIUM,
    browser,
    open_page,
    page,
    server,
    settle,
    web_drag,
)

pytestmark = pytest.mark.skipif(not CHROMIUM.exists(), reason=f"{CHROMIUM} is missing")

HIGH = TIERS["high"].render_settings()
# (preset, fields): defaults of the preset and of the tier dropped, the fixed order, and
# floats whose Python and JavaScript spellings differ (exponents, 0.1 + 0.2).
CASES = [
    ("sphere", {}),
    ("sphere", {"quality": "standard", "width": 256}),
    ("cd-rom", {"mu_f": 7.25, "quality": "high"}),
    ("cd-rom", {"quality": "high", "samples": HIGH["samples"], "aa": HIGH["aa"]}),
    ("cd-rom", {"quality": "draft", "samples": HIGH["samples"], "wavelengths": 32}),
    ("sphere", {"exposure": 0.1 + 0.2, "theta1": 1e-05, "theta2": -1.5e-07}),
    ("sphere", {"ex": 123456.789, "ey": 1e-4, "alpha": 2.0}),
    ("sphere", {"albedo": [0.2, 1 / 3, 1.0], "transparent": True, "format": "webp"}),
    ("sphere", {"light_azimuth": -0.0, "light_elevation": 12.5, "tonemap": "aces"}),
    ("sphere", {"environment": "sky", "environment_rotation": 90.0,
                "environment_lights": 4, "width": 64, "height": 48}),
    # A film takes its own wavelengths from the tier (0 at standard on a dielectric, 16 on
    # a metal): the tier's own value is dropped, the rotation's spelt.
    ("oil-film", {"quality": "standard", "wavelengths": 0}),
    ("oil-film", {"quality": "standard", "wavelengths": 16}),
    ("oil-film", {"quality": "standard", "substrate": "conductor", "wavelengths": 16}),
    ("sphere", {"iridescence": "thin-film", "wavelengths": 0}),
    ("tempered-steel", {"quality": "draft", "wavelengths": 0, "substrate": "dielectric"}),
    # A stack takes the tier's stack_wavelengths (32 at standard, where a film takes 0).
    ("bragg-mirror", {"quality": "standard", "wavelengths": 32}),
    ("bragg-mirror", {"quality": "standard", "wavelengths": 0}),
    ("oil-film", {"quality": "standard", "film_stack_pairs": 3, "wavelengths": 32}),
]


def without_rev(path: str) -> str:
    """The query of a canonical URL less its rev, which only the service can compute."""
    query = path.partition("?")[2]
    return "&".join(p for p in query.split("&") if not p.startswith("rev="))


SPELL = """async (cases) => {
  const { canonicalQuery } = await import('/static/canonical.js');
  const spelt = [];
  for (const [preset, fields] of cases) {
    const info = await (await fetch(`/v1/presets/${preset}`)).json();
    spelt.push(canonicalQuery(preset, fields, info));
  }
  return spelt;
}"""


def test_the_page_spells_each_request_as_the_service_does(page):  # noqa: F811
    """canonical.js and pipeline/canonical.py give one query string per request."""
    open_page(page)
    spelt = page.evaluate(SPELL, [list(case) for case in CASES])
    expected = [without_rev(canonical_path(RenderRequest(preset=preset, **fields)))
                for preset, fields in CASES]
    assert spelt == expected
    assert expected[0] == expected[1] == ""  # every default dropped, the default preset too


def test_previews_and_drafts_are_gets_of_the_canonical_urls(page):  # noqa: F811
    """Every render the page asks for (preview, then drafts while the light is dragged) is a
    GET of the URL its answer names in Content-Location, less the rev."""
    answers: list[tuple[str, str, str, str]] = []
    # A 503 (the workers still warming up) names no image; the page asks again.
    page.on("response", lambda r: answers.append(
        (r.request.method, r.url, r.headers.get("content-location", ""),
         r.headers.get("content-type", ""))) if "/v1/render" in r.url and r.status != 503
        else None)
    # The link's samples are the tier's own: dropped from the preview's URL.
    open_page(page, f"?preset=cd-rom&samples={HIGH['samples']}&quality=high")
    page.fill("#in-mu_f", "7.25")
    settle(page)
    page.evaluate(web_drag.PREVIEW_256)
    web_drag.drag_preview(page, 1.0, lambda: settle(page))
    assert len(answers) >= 4
    for method, url, location, kind in answers:
        parts = urlsplit(url)
        assert method == "GET" and location.startswith(f"{parts.path}?"), (url, location)
        assert parts.query == without_rev(location), (url, location)
        assert kind == "image/png"
    queries = [urlsplit(url).query for _, url, _, _ in answers]
    assert queries[:2] == ["preset=cd-rom&quality=high", "preset=cd-rom&quality=high&mu_f=7.25"]
    assert any("quality=draft" in q for q in queries)
