"""Live preview while dragging: preview updates per second in headless Chromium.

    python bench/web_drag.py [--seconds 5] [--preset sphere]

Starts ``opaline serve`` (one worker) on loopback, opens the tuning page with
the preview shown at 256 CSS px (so the drafts are 256² at devicePixelRatio 1),
presses on it and moves the light in small steps every 16 ms, and counts the
draft frames the page shows (``data-live-frames``). Then the same with
``environment=studio`` (issue 21: ≥ 10 updates/s with an environment on), twice: the
light pad again (the environment replaces the key light, so the picture stays, but
each step is a fresh render: light_azimuth is in the cache key), and the
environment_rotation slider swept once from left to right (each step a new value,
none repeated). Requests that repeat an earlier one (a cache may answer them) are
counted.
Writes bench/results/web_drag.json. tests/web/test_web.py uses ``drag_preview`` too.
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


def wiggle(box: dict, moves: int, _progress: float) -> tuple[float, float]:
    """About the centre of ``box``, never far from where the press was."""
    return (box["x"] + box["width"] / 2 + 40 * math.sin(moves / 10),
            box["y"] + box["height"] / 2 + 20 * math.cos(moves / 13))


def sweep(box: dict, _moves: int, progress: float) -> tuple[float, float]:
    """Left to right along ``box`` (a slider) once, over the drag's time."""
    return box["x"] + box["width"] * (0.05 + 0.9 * min(progress, 1.0)), box["y"] + box["height"] / 2


def drag_preview(page, seconds: float, settle, step_ms: int = 16, target: str = "#stage",
                 path=wiggle) -> dict:
    """Press on ``target`` (the preview) and move along ``path`` in small steps for
    ``seconds``; how many draft frames the page showed, the most renders ever in flight
    at once, the render URLs and how many of them repeat an earlier one."""
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
    page.locator(target).scroll_into_view_if_needed()
    box = page.locator(target).bounding_box()
    page.mouse.move(*path(box, 0, 0.0))
    page.mouse.down()

    def frames() -> int:
        return int(page.evaluate("document.body.dataset.liveFrames || '0'"))

    first, start, moves = frames(), time.perf_counter(), 0
    while (elapsed := time.perf_counter() - start) < seconds:
        moves += 1
        page.mouse.move(*path(box, moves, elapsed / seconds))
        page.wait_for_timeout(step_ms)
    seen["seconds"] = time.perf_counter() - start
    seen["frames"] = frames() - first
    page.mouse.up()
    settle()
    # A state asked for twice may come from the browser's cache or the service's.
    seen["repeats"] = len(seen["urls"]) - len(set(seen["urls"]))
    for event, handler in (("request", started), ("requestfinished", ended),
                           ("requestfailed", ended)):
        page.remove_listener(event, handler)
    return seen


# (what is dragged, the page's query beyond preset and tier, the element, the path)
DRAGS = (("light pad", "", "#stage", wiggle),
         ("light pad", "&environment=studio", "#stage", wiggle),
         ("environment_rotation slider", "&environment=studio", "#rng-environment_rotation",
          sweep))


def measure(base: str, preset: str, seconds: float) -> list[dict]:
    """Each of ``DRAGS`` on a freshly opened page, in one browser."""
    from playwright.sync_api import sync_playwright

    rows = []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        page = browser.new_context(viewport={"width": 1280, "height": 800}).new_page()

        def settle() -> None:
            wait_true(page, "document.body.dataset.busy === 'false'")

        for what, query, target, path in DRAGS:
            page.goto(f"{base}/?preset={preset}&quality=high{query}")
            settle()
            page.evaluate(PREVIEW_256)
            seen = drag_preview(page, seconds, settle, target=target, path=path)
            rows.append({"drag": what, "environment": query.partition("=")[2] or None,
                         "seconds": seen["seconds"], "frames": seen["frames"],
                         "updates_per_s": seen["frames"] / seen["seconds"],
                         "max_in_flight": seen["max"], "requests": len(seen["urls"]),
                         "repeated": seen["repeats"]})
        browser.close()
    return rows


def main() -> None:
    from opaline.server.localserver import LocalServer

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--preset", default="sphere")
    args = parser.parse_args()
    with LocalServer(workers=1, ready_path="/readyz") as local:
        rows = measure(local.base, args.preset, args.seconds)
    from report import save  # here: tests load this module without bench/ on the path

    save("web_drag", {"preset": args.preset, "drags": rows})
    for row in rows:
        print(f"{args.preset}, {row['drag']}, environment {row['environment'] or 'none'}, "
              f"256² draft while dragging: {row['updates_per_s']:.1f} updates/s "
              f"({row['frames']} frames in {row['seconds']:.1f} s, {row['repeated']} of "
              f"{row['requests']} renders asked for before, at most {row['max_in_flight']} "
              "in flight)")


if __name__ == "__main__":
    main()
