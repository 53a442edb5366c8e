"""The web page works end to end in a real headless Chromium against a real service."""

from __future__ import annotations

import base64
import shlex
import subprocess
import time
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest

from bench_metrics import load_bench
from opaline.model.tiers import TIERS
from opaline.server.localserver import LocalServer, ServerError, loopback_env

CHROMIUM = Path("/usr/bin/chromium")
# Only 127.0.0.1 traffic: no background networking, updates, sync or QUIC probes.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"]
# The longest any one step may take in the browser. The first preview waits out the
# start-up calibration's predicted time (its Retry-After): 4 renders a preset at the
# uncalibrated cost model, 14 s for 17 presets (calibration.CalibrateTask.units), which had
# outgrown 15 s with the page's own work.
WAIT_MS = 30_000
# The service's start-up: worker thread, GL context, warm-up, calibration (with an empty
# shader cache 30 s on EGL here, 2 cores; CI's machine has run 1.3× slower).
START_S = 120.0

web_drag = load_bench("web_drag")

pytestmark = pytest.mark.skipif(not CHROMIUM.exists(),
                                reason=f"{CHROMIUM} is missing (Debian's chromium package)")


@pytest.fixture(scope="module")
def server():
    """``opaline serve`` as a real uvicorn process on a free port of 127.0.0.1, once ready
    (/readyz: calibrated). Before, the page opened at /healthz met the calibration's 503 and
    its Retry-After of 16 s, half of a wait's 30 s on a loaded machine."""
    try:
        with LocalServer(workers=1, ready_path="/readyz", start_timeout_s=START_S) as local:
            yield local.base
    except ServerError as exc:
        pytest.fail(str(exc))


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        chromium = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS,
                                      timeout=WAIT_MS)
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser, server):
    """A fresh page; fails the test on any uncaught script error."""
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    context.set_default_timeout(WAIT_MS)
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.base = server  # type: ignore[attr-defined]
    yield page
    context.close()
    assert not errors, f"script errors in the page: {errors}"


def open_page(page, query: str = ""):
    page.goto(f"{page.base}/{query}")
    settle(page)


def wait_until(page, expression: str, arg=None, timeout_ms: int = WAIT_MS) -> None:
    """Poll ``expression`` (a JS function of ``arg``) until it is true.

    Playwright's wait_for_function evaluates its predicate with eval, which the pages'
    Content-Security-Policy forbids (no 'unsafe-eval'); page.evaluate goes through the
    DevTools protocol, which the policy does not govern."""
    deadline = time.monotonic() + timeout_ms / 1000
    while not page.evaluate(expression, arg):
        if time.monotonic() > deadline:
            raise AssertionError(f"not true within {timeout_ms} ms: {expression}")
        time.sleep(0.05)


def settle(page) -> None:
    """Wait until the page has no change pending and every answer is shown."""
    wait_until(page, "() => document.body.dataset.busy === 'false'")


def shown_bytes(page, selector: str = "#preview") -> bytes:
    """The bytes of the image the page shows (its object URL, read back)."""
    data = page.evaluate(
        """async (selector) => {
             const img = document.querySelector(selector);
             if (!img.src.startsWith('blob:')) return null;
             const bytes = new Uint8Array(await (await fetch(img.src)).arrayBuffer());
             let text = '';
             for (let i = 0; i < bytes.length; i += 8192) {
               text += String.fromCharCode(...bytes.subarray(i, i + 8192));
             }
             return btoa(text);
           }""", selector)
    assert data, f"{selector} shows no fetched image"
    return base64.b64decode(data)


def test_page_loads_with_controls_from_the_schema(page):
    """The page loads, shows a PNG preview and MDF plot, and takes its ranges from the API."""
    open_page(page)
    assert page.title().startswith("Opaline")
    assert shown_bytes(page).startswith(b"\x89PNG")
    assert shown_bytes(page, "#mdf").startswith(b"\x89PNG")
    assert page.input_value("#preset") == "sphere"
    assert page.get_attribute("#in-mu_f", "max") == "1000"
    assert page.get_attribute("#in-theta1", "min").startswith("-6.28")
    assert "Multi-peak frequency" in page.text_content("#desc-mu_f")
    for name in ("mdf", "ex", "ey", "mu_f", "alpha", "beta", "theta1", "theta2", "kd", "ks",
                 "f0", "light_azimuth", "light_elevation", "width", "height", "quality",
                 "format"):
        assert page.locator(f"#in-{name}").count() == 1, name
    assert page.locator("#rng-ex").count() == 1 and page.locator("#in-albedo-0").count() == 1
    tonemaps = page.eval_on_selector_all("#in-tonemap option", "os => os.map(o => o.value)")
    assert tonemaps == ["none", "reinhard", "aces", "neutral"]
    assert page.input_value("#in-tonemap") == "neutral"  # the default, shown as chosen
    # A colour has a picker; a direction has none, and shows nothing while unset (it had a
    # colour picker and showed 0,0,0 where the default is 0,1,0).
    assert page.locator("#in-albedo-color").count() == 1
    assert page.locator("#in-tangent_axis-color").count() == 0
    assert page.input_value("#in-tangent_axis-1") == ""
    # An unset tier field's slider stands at the tier's value (it stood at the range's
    # minimum, 1 sample, where standard takes 4), and says so.
    standard = TIERS["standard"].samples
    assert page.get_attribute("#rng-samples", "aria-valuetext") == f"tier's value: {standard}"
    assert page.input_value("#rng-samples") != page.get_attribute("#rng-samples", "min")


def test_preset_and_slider_change_the_preview(page):
    """Choosing a preset, then moving a slider, each change the preview's bytes."""
    open_page(page)
    sphere = shown_bytes(page)
    page.select_option("#preset", "cd-rom")
    settle(page)
    cd_rom = shown_bytes(page)
    assert cd_rom != sphere
    assert page.input_value("#in-mu_f") == "8.5"
    page.focus("#rng-mu_f")
    for _ in range(3):
        page.keyboard.press("ArrowRight")
    settle(page)
    assert page.input_value("#in-mu_f") != "8.5"
    assert shown_bytes(page) != cd_rom
    assert "mu_f=" in page.get_attribute("#preview", "data-url")


def test_out_of_range_value_shows_the_api_message_by_its_control(page):
    """mu_f=2000 shows the API's 422 line beside mu_f and keeps the last good image."""
    open_page(page, "?preset=cd-rom")
    good = shown_bytes(page)
    page.fill("#in-mu_f", "2000")
    settle(page)
    message = page.locator('.field[data-field="mu_f"] .error')
    assert message.is_visible()
    text = message.text_content()
    assert text.startswith("mu_f=") and "out of range" in text and "1000" in text, text
    assert page.get_attribute("#in-mu_f", "aria-invalid") == "true"
    assert page.locator("#err-general").is_hidden()
    assert shown_bytes(page) == good
    page.fill("#in-mu_f", "9")
    settle(page)
    assert message.is_hidden()
    assert shown_bytes(page) != good


def test_environment_picker_backdrop_and_blur(page):
    """The environment group picks a built-in (listed from the schema) or a typed file
    name, and its backdrop and blur controls change the preview; the quick picker by the
    mesh drop shows the same choice."""
    open_page(page)
    options = page.eval_on_selector_all("#in-environment option", "os => os.map(o => o.text)")
    assert options == ["preset's", "studio", "neutral", "sky", "none", "file…"], options
    assert page.locator("#in-environment-file").is_hidden()
    plain = shown_bytes(page)
    page.select_option("#in-environment", "neutral")
    settle(page)
    lit = shown_bytes(page)
    assert lit != plain and "environment=neutral" in page.get_attribute("#preview", "data-url")
    assert page.input_value("#env-pick") == "neutral"
    page.check("#in-environment_background")
    settle(page)
    backdrop = shown_bytes(page)
    assert backdrop != lit
    page.select_option("#in-environment", "studio")
    settle(page)
    sharp = shown_bytes(page)
    page.fill("#in-environment_blur", "0.5")
    settle(page)
    assert "environment_blur=0.5" in page.get_attribute("#preview", "data-url")
    assert shown_bytes(page) != sharp
    page.select_option("#in-environment", label="file…")
    assert page.locator("#in-environment-file").is_visible()
    page.select_option("#env-pick", "sky")
    settle(page)
    assert page.input_value("#in-environment") == "sky"
    assert page.locator("#in-environment-file").is_hidden()


def test_quick_picker_gives_the_presets_lights_and_names_a_file(page):
    """On a preset lit by a map by default, "the preset's lights" is environment=none (it
    snapped back to the studio); a file's name shows as itself (it showed "the preset's
    lights"); an unknown file's 404 is shown by the environment control, not at the top."""
    open_page(page, "?preset=soap-bubble")
    assert page.input_value("#env-pick") == "studio"
    page.select_option("#env-pick", "none")
    settle(page)
    assert "environment=none" in page.get_attribute("#preview", "data-url")
    assert page.input_value("#env-pick") == "none"
    page.select_option("#in-environment", label="file…")
    page.fill("#in-environment-file", "nowhere.hdr")
    page.press("#in-environment-file", "Enter")
    settle(page)
    assert page.input_value("#env-pick") == "nowhere.hdr"
    assert "nowhere.hdr" in page.text_content("#err-environment")
    assert page.locator("#err-environment").is_visible()


def test_copied_curl_returns_the_shown_bytes(page, tmp_path):
    """Dragging the preview moves the light; "Copy as curl", run, gets the bytes shown."""
    open_page(page, "?preset=cd-rom")
    page.fill("#in-theta2", "0.5")
    box = page.locator("#stage").bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] * 0.7, box["y"] + box["height"] * 0.4, steps=4)
    page.mouse.up()
    settle(page)
    azimuth = page.input_value("#in-light_azimuth")
    assert azimuth not in ("", "0") and page.input_value("#in-light_elevation") != ""
    page.focus("#stage")
    page.keyboard.press("ArrowLeft")
    settle(page)
    assert float(page.input_value("#in-light_azimuth")) == pytest.approx(float(azimuth) - 5)
    shown = shown_bytes(page)

    page.check('input[name="copy-kind"][value="curl"]')
    assert page.locator("#copy-curl").is_visible()
    command = shlex.split(page.input_value("#copy-curl"))
    assert command[0] == "curl" and "-o" in command
    out = tmp_path / command[command.index("-o") + 1]
    run = subprocess.run(command, cwd=tmp_path, env=loopback_env(), capture_output=True,
                         timeout=30, check=False)
    assert run.returncode == 0, run.stderr.decode()
    assert out.read_bytes() == shown


def test_shareable_url_restores_the_state(page, browser):
    """The page's link, opened afresh, restores every control and the same image."""
    open_page(page)
    page.select_option("#preset", "oil-slick")
    settle(page)
    page.fill("#in-mu_f", "12")
    page.select_option("#in-quality", "draft")
    page.fill("#in-albedo-0", "0.2")
    page.fill("#in-width", "320")
    settle(page)
    link = page.input_value("#copy-url")
    assert link.startswith(page.base) and "preset=oil-slick" in link
    body = page.input_value("#copy-json")
    shown = shown_bytes(page)

    other = browser.new_page(viewport={"width": 800, "height": 700})
    try:
        other.goto(link)
        settle(other)
        assert other.input_value("#preset") == "oil-slick"
        assert other.input_value("#in-mu_f") == "12"
        assert other.input_value("#in-quality") == "draft"
        assert other.input_value("#in-albedo-0") == "0.2"
        assert other.input_value("#in-width") == "320"
        assert other.input_value("#copy-json") == body
        assert shown_bytes(other) == shown
    finally:
        other.close()


def test_busy_service_is_shown_and_retried(page):
    """A 503 with Retry-After shows its message, keeps the image, and is retried after it."""
    open_page(page, "?preset=cd-rom")
    good = shown_bytes(page)
    refused: list[str] = []

    def busy_once(route):
        if refused:
            route.continue_()
            return
        refused.append(route.request.url)
        route.fulfill(status=503, headers={"Retry-After": "1"}, content_type="application/json",
                      body='{"error": "queue_full", "detail": ["the render queue is full; retry later"]}')

    page.route("**/v1/render?*", busy_once)
    page.fill("#in-mu_f", "7")
    wait_until(page, "() => document.querySelector('#err-general').textContent"
                     ".includes('queue is full')")
    assert "busy" in page.text_content("#status")
    assert shown_bytes(page) == good
    settle(page)
    assert len(refused) == 1 and page.locator("#err-general").is_hidden()
    assert shown_bytes(page) != good


def test_invalid_value_during_a_render_stops_the_spinner(page):
    """A value made invalid while a render is in flight ends the loading state with the wait."""
    open_page(page, "?preset=cd-rom")
    held: list = []
    page.route("**/v1/render?*", lambda route: held.append(route))  # held: never answered
    page.fill("#in-mu_f", "7")
    wait_until(page, "() => document.body.classList.contains('loading')")
    page.fill("#in-mu_f", "")
    settle(page)
    assert held and "valid value" in page.text_content("#status")
    assert not page.evaluate("document.body.classList.contains('loading')")
    page.unroute("**/v1/render?*")  # the held request was aborted by the page itself


# Offline documentation and access control (issue 11)


def only_the_service(page, base: str) -> tuple[list[str], list[str]]:
    """Abort and record every request that leaves the service; record CSP violations."""
    outside: list[str] = []
    violations: list[str] = []

    def guard(route):
        if route.request.url.startswith(base):
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    page.route("**/*", guard)
    page.on("console", lambda msg: violations.append(msg.text)
            if "Content Security Policy" in msg.text else None)
    return outside, violations


def test_docs_render_with_no_network_but_the_service(page):
    """Swagger UI comes from the service itself, under its CSP, and shows every route."""
    outside, violations = only_the_service(page, page.base)
    answer = page.goto(page.base + "/docs")
    assert "frame-ancestors 'none'" in answer.headers["content-security-policy"]
    assert answer.headers["x-content-type-options"] == "nosniff"
    wait_until(page, "(sel) => [...document.querySelectorAll(sel)]"
                     ".some((n) => n.textContent.includes('Opaline'))", ".swagger-ui .info .title")
    page.wait_for_selector(".opblock-summary-path[data-path='/v1/render']", timeout=WAIT_MS)
    assert outside == [] and violations == []


def test_page_works_with_keys_and_signing_on(browser):
    """With access control on, the page asks for a key, sends it as a header (never in a
    URL), and then shows the preview as before."""
    key = "web-key-7d2e"
    env = {"OPALINE_API_KEYS": key, "OPALINE_SIGNING_KEY": "web-secret-19aa"}
    try:
        with LocalServer(workers=1, env=env, ready_path="/readyz", start_timeout_s=START_S) as local:
            context = browser.new_context()
            context.set_default_timeout(WAIT_MS)
            page = context.new_page()
            outside, violations = only_the_service(page, local.base)
            urls: list[str] = []
            page.on("request", lambda request: urls.append(request.url))
            answer = page.goto(local.base + "/")
            assert "script-src 'self'" in answer.headers["content-security-policy"]
            page.wait_for_selector("#key-form:not([hidden])")
            page.fill("#api-key", key)
            page.click("#key-form button")
            settle(page)
            assert shown_bytes(page).startswith(b"\x89PNG")
            assert page.locator("#key-form").is_hidden()
            context.close()
    except ServerError as exc:
        pytest.fail(str(exc))
    assert outside == [] and violations == []
    assert not any(key in url for url in urls)


def test_dragging_shows_drafts_one_at_a_time_then_the_chosen_tier(page):
    """While the light is dragged the preview shows draft renders (PNG, at the
    displayed size × devicePixelRatio) as they come, never more than one in flight; on
    release it shows the chosen tier. The rate is printed (bench/web_drag.py measures it)."""
    open_page(page, "?preset=sphere&quality=high")
    page.evaluate(web_drag.PREVIEW_256)
    seen = web_drag.drag_preview(page, 1.5, lambda: settle(page))
    print(f"live preview: {seen['frames'] / seen['seconds']:.1f} updates/s")
    assert seen["max"] == 1, f"{seen['max']} renders were in flight at once"
    drafts = [u for u in seen["urls"] if "quality=draft" in u]
    assert seen["frames"] >= 3 and len(drafts) >= seen["frames"]
    size = page.evaluate("Math.round(document.querySelector('#preview')"
                         ".getBoundingClientRect().width * devicePixelRatio)")
    # Canonical URLs (test_web_canonical.py): PNG and the preset's 256 wide go unsaid.
    widths = [parse_qs(urlsplit(u).query).get("width", ["256"]) for u in drafts]
    assert widths == [[str(size)]] * len(drafts) and not any("format=" in u for u in drafts)
    final = page.get_attribute("#preview", "data-url")
    assert "quality=high" in final and "light_azimuth=" in final
