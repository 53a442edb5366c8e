"""Draw + readback and PNG encoding times per backend, at 256² and 1024².

    .venv/bin/python bench/render_speed.py [--repeats 5] [--backends egl osmesa]

Each backend runs in its own process (EGL and OSMesa share Mesa's dispatch).
Prints a table and writes bench/results/render_speed.{json,md}.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys
import time

from report import save  # bench/report.py: run from bench/, it is on the path

SIZES = (256, 1024)


def measure(backend: str, repeats: int) -> dict:
    """Run inside a child process: median seconds per stage for every preset and size."""
    from opaline.gl.renderer import Renderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import all_presets, get_preset
    from opaline.model.request import resolve
    from opaline.output.encode import encode_frame

    renderer = Renderer(backend)
    rows = []
    for size in SIZES:
        for name in all_presets():
            job = resolve(RenderRequest(preset=name, width=size, height=size), get_preset(name))
            renderer.render(job)  # warm-up: compile, upload
            draw, encode = [], []
            for _ in range(repeats):
                start = time.perf_counter()
                frame = renderer.render(job)
                middle = time.perf_counter()
                encode_frame(frame, "png")
                draw.append(middle - start)
                encode.append(time.perf_counter() - middle)
            rows.append(
                {
                    "preset": name,
                    "size": size,
                    "samples": job.samples,
                    "draw_readback_ms": 1e3 * statistics.median(draw),
                    "png_encode_ms": 1e3 * statistics.median(encode),
                }
            )
    info = renderer.gl.describe()
    renderer.release()
    return {"backend": backend, "renderer": info["renderer"], "rows": rows}


def markdown(results: list[dict], repeats: int) -> str:
    lines = [
        f"Machine: {platform.machine()}, {platform.system()}, Python {platform.python_version()}; "
        f"median of {repeats} warm renders, standard tier (4 samples).",
        "",
        "| backend | size | draw + readback, median over presets (ms) | slowest preset (ms) "
        "| PNG encode (ms) |",
        "|---|---|---|---|---|",
    ]
    for result in results:
        for size in SIZES:
            rows = [r for r in result["rows"] if r["size"] == size]
            draws = [r["draw_readback_ms"] for r in rows]
            slowest = max(rows, key=lambda r: r["draw_readback_ms"])
            lines.append(
                f"| {result['backend']} ({result['renderer']}) | {size}² | "
                f"{statistics.median(draws):.1f} | {slowest['draw_readback_ms']:.1f} "
                f"({slowest['preset']}) | {statistics.median(r['png_encode_ms'] for r in rows):.1f} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--backends", nargs="+", default=["egl", "osmesa"])
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(args.child, args.repeats)))
        return
    results = []
    for backend in args.backends:
        out = subprocess.run(
            [sys.executable, __file__, "--child", backend, "--repeats", str(args.repeats)],
            check=True,
            capture_output=True,
            text=True,
        )
        results.append(json.loads(out.stdout.strip().splitlines()[-1]))
    save("render_speed", results, markdown(results, args.repeats))


if __name__ == "__main__":
    main()
