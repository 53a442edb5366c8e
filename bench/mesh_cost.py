"""A stored mesh costs what a preset of the same triangles costs: the sphere preset against
the same sphere exported as .glb and rendered as a user's mesh, warm, same size and tier.

    python bench/mesh_cost.py [--size 256] [--repeat 9]

Also times a 36-frame turntable at 256² per animation format. Prints the figures and
writes bench/results/mesh_cost.{md,json}.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "service")]
from opaline.local.export import export_material  # noqa: E402
from opaline.local.pipeline import LocalRenderer  # noqa: E402
from opaline.local.turntable import turntable_bytes  # noqa: E402
from opaline.model.params import RenderRequest  # noqa: E402
from opaline.model.turntable import TurntableRequest  # noqa: E402
from report import save  # noqa: E402


def timed(local: LocalRenderer, request: RenderRequest, repeat: int) -> float:
    prepared = local.prepare(request)
    local.produce(prepared)  # upload and compile
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        local.produce(prepared)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp, LocalRenderer() as local:
        glb = Path(tmp) / "sphere.glb"
        glb.write_bytes(export_material({"preset": "sphere"}, "glb"))
        common = {"width": args.size, "height": args.size, "quality": "standard"}
        preset_s = timed(local, RenderRequest(preset="sphere", **common), args.repeat)
        mesh_s = timed(local, RenderRequest(preset="sphere", mesh=str(glb), **common),
                       args.repeat)
        turntables = {}
        for fmt in ("webp", "gif", "mp4"):
            start = time.perf_counter()
            turntable_bytes(local, TurntableRequest(preset="cd-rom", animation=fmt))
            turntables[fmt] = time.perf_counter() - start
    result = {"size": args.size, "preset_ms": preset_s * 1e3, "mesh_ms": mesh_s * 1e3,
              "ratio": mesh_s / preset_s,
              "turntable_36x256_standard_s": turntables}
    lines = [f"# Mesh cost and turntable time ({args.size}², standard tier)", "",
             "Command: `python bench/mesh_cost.py`.", "",
             f"- sphere preset: {result['preset_ms']:.1f} ms; the same sphere as a stored "
             f".glb: {result['mesh_ms']:.1f} ms (ratio {result['ratio']:.2f})",
             *[f"- 36-frame turntable of cd-rom at 256², standard, {fmt}: {s:.2f} s"
               for fmt, s in turntables.items()]]
    save("mesh_cost", result, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
