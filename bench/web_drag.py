"""Live preview while dragging: preview updates per second in headless Chromium.

    python bench/web_drag.py [--seconds 5] [--preset sphere]

Starts ``opaline serve`` (one worker) on loopback, opens the tuning page with
the preview shown at 256 CSS px (so the drafts are 256² at devicePixelRatio 1),
presses on it and moves the light in small steps every 16 ms, and counts the
draft frames the page shows (``data-live-frames``). Writes
bench/results/web_drag.json. tests/web/test_web.py uses ``drag_preview`` too.
"""

from __future__ import annotations

import argparse
import math
import time

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
# Set through the CSSOM: the page's Content-Security-Policy forbids inline <style> (and the
# eval that Playwright's wait_for_function uses), not scripts run over DevTools.
PREVIEW_256 = ("(() => { const s = document.querySelector('#preview').style;"
               " s.setProperty('width', '256px', 'important');"
               " s.setProperty('height', 'auto', 'important'); })()")


def wait_true(page, expression: str, timeout_s: float = 30.0) -> None:
    """Poll a JS expression through page.evaluate (not eval, which the CSP forbids)."""
    import time

    deadline = time.monotonic() + timeout_s
    while not page.evaluate(expression):
        if time.monotonic() > deadline:
            raise TimeoutError(f"not true within {timeout_s:g} s: {expression}")
        time.sleep(0.02)


def drag_preview(page, seconds: float, settle, step_ms: int = 16) -> dict:
    """Press on the preview and move in small steps for ``seconds``; how many draft frames
    the page showed, the most renders ever in flight at once, and the render URLs."""
    seen: dict = {"now": 0, "max": 0, "urls": []}

    def started(request) -> None:
        if "/v1/render" in request.url:
            seen["now"] += 1
            seen["max"] = max(seen["max"], seen["now"])
            seen["urls"].append(request.url)

    def ended(request) -> None:
        if "/v1/render" in request.url:
            seen["now"] -= 1

    page.on("request", started)
    page.on("requestfinished", ended)
    page.on("requestfailed", ended)
    box = page.locator("#stage").bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()

    def frames() -> int:
        return int(page.evaluate("document.body.dataset.liveFrames || '0'"))

    first, start, moves = frames(), time.perf_counter(), 0
    while time.perf_counter() - start < seconds:
        moves += 1
        page.mouse.move(x + 40 * math.sin(moves / 10), y + 20 * math.cos(moves / 13))
        page.wait_for_timeout(step_ms)
    seen["seconds"] = time.perf_counter() - start
    seen["frames"] = frames() - first
    page.mouse.up()
    settle()
    return seen


def main() -> None:
    from playwright.sync_api import sync_playwright

    from opaline.server.localserver import LocalServer

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--preset", default="sphere")
    args = parser.parse_args()
    with LocalServer(workers=1, ready_path="/readyz") as local, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        page = browser.new_context(viewport={"width": 1280, "height": 800}).new_page()
        page.goto(f"{local.base}/?preset={args.preset}&quality=high")

        def settle() -> None:
            wait_true(page, "document.body.dataset.busy === 'false'")

        settle()
        page.evaluate(PREVIEW_256)
        seen = drag_preview(page, args.seconds, settle)
        browser.close()
    result = {"preset": args.preset, "seconds": seen["seconds"], "frames": seen["frames"],
              "updates_per_s": seen["frames"] / seen["seconds"], "max_in_flight": seen["max"],
              "requests": len(seen["urls"])}
    from report import save  # here: tests load this module without bench/ on the path

    save("web_drag", result)
    print(f"{args.preset}, 256² draft while dragging: {result['updates_per_s']:.1f} updates/s "
          f"({seen['frames']} frames in {seen['seconds']:.1f} s, at most {seen['max']} in flight)")


if __name__ == "__main__":
    main()
