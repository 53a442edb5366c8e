"""The bare-GL floor: the least a 256² PNG of a lit sphere can cost on this machine.

    python bench/floor/floor.py [--size 256] [--repeats 20] [--once OUT.png]

A ~4k-triangle unit sphere with one Blinn-Phong light, drawn by moderngl on a
headless EGL context straight into an RGBA8 framebuffer, read back as bytes
and written as PNG at zlib level 1. No tone map, no supersampling, no caching:
every Opaline figure in bench/speed.py is a ratio to this, measured in the
same run. ``--once`` is the cold script (import, context, one image, exit).
"""

from __future__ import annotations

import argparse
import io
import json
import statistics
import sys
import time
from pathlib import Path

import moderngl
import numpy as np
from PIL import Image

SOURCE = (Path(__file__).with_name("floor.glsl")).read_text()


def sphere(segments: int = 64, rings: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Unit-sphere vertices and triangle indices: 2·segments·(rings-1) ≈ 4k triangles."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    points = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1)
    index = np.arange((rings + 1) * (segments + 1)).reshape(rings + 1, segments + 1)
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    tris = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])
    return points.reshape(-1, 3).astype("f4"), tris.astype("u4")


def view_projection(aspect: float, eye=(0.0, 0.3, 3.4), fov_deg: float = 40.0) -> np.ndarray:
    f = 1.0 / np.tan(np.radians(fov_deg) / 2.0)
    near, far = 0.1, 100.0
    proj = np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])
    forward = -np.asarray(eye) / np.linalg.norm(eye)
    right = np.cross(forward, (0.0, 1.0, 0.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward
    view[:3, 3] = -view[:3, :3] @ np.asarray(eye)
    return proj @ view


class Floor:
    """Context, program, mesh and an RGBA8 target, made once; ``png()`` draws one image."""

    def __init__(self, size: int = 256) -> None:
        self.ctx = moderngl.create_standalone_context(backend="egl")
        self.size = (size, size)
        header = "#version 330 core\n#define {}\n"
        self.program = self.ctx.program(vertex_shader=header.format("VERTEX_SHADER") + SOURCE,
                                        fragment_shader=header.format("FRAGMENT_SHADER") + SOURCE)
        points, tris = sphere()
        self.triangles = len(tris)
        vbo, ibo = self.ctx.buffer(points.tobytes()), self.ctx.buffer(tris.tobytes())
        self.vao = self.ctx.vertex_array(self.program, [(vbo, "3f", "in_position")],
                                         index_buffer=ibo)
        self.program["u_view_proj"].write(view_projection(1.0).T.astype("f4").tobytes())
        self.program["u_eye"].value = (0.0, 0.3, 3.4)
        self.program["u_light"].value = (2.0, 2.5, 3.0)
        self.fbo = self.ctx.framebuffer([self.ctx.renderbuffer(self.size, 4)],
                                        self.ctx.depth_renderbuffer(self.size))

    def pixels(self) -> bytes:
        self.fbo.use()
        self.fbo.clear(0.1, 0.1, 0.11, 1.0, depth=1.0)
        self.ctx.enable(moderngl.DEPTH_TEST)
        self.vao.render(moderngl.TRIANGLES)
        return self.fbo.read(components=4)

    def png(self) -> bytes:
        raw = self.pixels()
        image = Image.frombytes("RGBA", self.size, raw).transpose(Image.Transpose.FLIP_TOP_BOTTOM)
        out = io.BytesIO()
        image.save(out, format="PNG", compress_level=1)
        return out.getvalue()


def timed(work) -> float:
    start = time.perf_counter()
    work()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--once", metavar="OUT.png", help="draw one image, write it, exit")
    parser.add_argument("--serve", action="store_true",
                        help="for bench/speed.py: read a count per line, answer the seconds "
                             "of each of that many images as a JSON list")
    args = parser.parse_args()
    floor = Floor(args.size)
    if args.once:
        Path(args.once).write_bytes(floor.png())
        return
    if args.serve:
        floor.png()  # warm
        for line in sys.stdin:
            print(json.dumps([timed(floor.png) for _ in range(int(line))]), flush=True)
        return
    floor.png()
    draw, total = [], []
    for _ in range(args.repeats):
        start = time.perf_counter()
        floor.pixels()
        middle = time.perf_counter()
        floor.png()
        total.append(time.perf_counter() - start)
        draw.append(middle - start)
    print(json.dumps({"triangles": floor.triangles, "draw_readback_ms": 1e3 * statistics.median(draw),
                      "png_ms": 1e3 * statistics.median(total)}))


if __name__ == "__main__":
    main()
