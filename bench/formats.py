"""Bytes and encode time per output format and preset, at 256², draft and standard.

    python bench/formats.py [--repeats 9]

One warm renderer draws each preset once per tier; each format then encodes
the same pixels ``repeats`` times (median). ``png`` is the service's (ISA-L
deflate, level 1); the same PNG through zlib at levels 1 and 6 (the old
default) is listed beside it, as the measurement behind the choice. Writes bench/results/formats.{json,md}.
"""

from __future__ import annotations

import argparse
import statistics
import time
import zlib

from report import save  # bench/report.py: run from bench/, it is on the path

FORMATS = ("png", "png-zlib1", "png-zlib6", "webp", "webp-lossless", "avif", "jpeg")


def encoder(fmt: str):
    from opaline.output import encode

    if fmt.startswith("png-zlib"):  # the same PNG through zlib at another level
        level = int(fmt.removeprefix("png-zlib"))

        def with_zlib(pixels):
            saved = encode.deflater, encode.PNG_LEVEL
            encode.deflater, encode.PNG_LEVEL = zlib, level
            try:
                return encode.png_pixels(pixels)
            finally:
                encode.deflater, encode.PNG_LEVEL = saved
        return with_zlib
    return lambda pixels: encode.encode_frame(type("F", (), {"pixels": pixels})(), fmt)


def measure(repeats: int) -> list[dict]:
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import all_presets
    from opaline.model.request import resolve

    renderer = Renderer()
    rows = []
    for name, preset in all_presets().items():
        for quality in ("draft", "standard"):
            job = resolve(RenderRequest(preset=name, quality=quality), preset)
            pixels = renderer.render(job).pixels
            for fmt in FORMATS:
                encode = encoder(fmt)
                data = encode(pixels)
                times = []
                for _ in range(repeats):
                    start = time.perf_counter()
                    encode(pixels)
                    times.append(time.perf_counter() - start)
                rows.append({"preset": name, "quality": quality, "format": fmt,
                             "bytes": len(data), "ms": 1e3 * statistics.median(times)})
    renderer.release()
    return rows


def markdown(rows: list[dict]) -> str:
    lines = [f"256², median encode time (ms) and size (KB) per format; png: ISA-L level 1, "
             f"png-zlibN: zlib {zlib.ZLIB_VERSION} level N; Pillow for the others.", "",
             "| preset | tier | " + " | ".join(FORMATS) + " |",
             "|---|---|" + "---|" * len(FORMATS)]
    keyed = {(r["preset"], r["quality"], r["format"]): r for r in rows}
    for preset, quality in dict.fromkeys((r["preset"], r["quality"]) for r in rows):
        cells = [f"{keyed[preset, quality, f]['ms']:.1f} ms, "
                 f"{keyed[preset, quality, f]['bytes'] / 1024:.1f} KB" for f in FORMATS]
        lines.append(f"| {preset} | {quality} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args()
    rows = measure(args.repeats)
    save("formats", rows, markdown(rows))


if __name__ == "__main__":
    main()
