"""What a renderer keeps on the GPU between renders.

Framebuffers for each image size, and each preset's mesh and normal map,
made once in the renderer's context and released with it: moderngl does not
release attachments with their framebuffer, and Python's collector must not do
it from another thread (docs/design.md §10).
"""

from __future__ import annotations

import moderngl
import numpy as np

from opaline.model.presets import Preset, build_assets


class Targets:
    """Framebuffers for one image size, kept and reused."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        self.size = size
        self.sample_tex = ctx.texture(size, 4, dtype="f4")
        self.depth = ctx.depth_renderbuffer(size)
        self.sample_fbo = ctx.framebuffer([self.sample_tex], self.depth)
        self.accum_tex = ctx.texture(size, 4, dtype="f4")
        self.accum_fbo = ctx.framebuffer([self.accum_tex])
        self.display_tex = ctx.texture(size, 4, dtype="f4")
        self.display_fbo = ctx.framebuffer([self.display_tex])

    def release(self) -> None:
        for obj in (
            self.sample_fbo,
            self.accum_fbo,
            self.display_fbo,
            self.sample_tex,
            self.depth,
            self.accum_tex,
            self.display_tex,
        ):
            obj.release()


class SceneGPU:
    """A preset's mesh and normal map, uploaded once."""

    def __init__(self, ctx: moderngl.Context, preset: Preset) -> None:
        mesh, normal_map = build_assets(preset)
        self.vbo = ctx.buffer(mesh.interleaved().astype("f4").tobytes())
        self.ibo = ctx.buffer(mesh.indices.astype("u4").tobytes())
        self.normal_map = None
        if normal_map is not None:
            height, width = normal_map.shape[:2]
            # Rows flipped: the map's row 0 is v = 1 (image convention), GL's is v = 0.
            data = np.ascontiguousarray(normal_map[::-1].astype("f4"))
            self.normal_map = ctx.texture((width, height), 3, data.tobytes(), dtype="f4")
            self.normal_map.build_mipmaps()
            self.normal_map.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            self.normal_map.repeat_x = self.normal_map.repeat_y = True
        self._vaos: dict[int, moderngl.VertexArray] = {}

    def vao(self, ctx: moderngl.Context, program: moderngl.Program) -> moderngl.VertexArray:
        found = self._vaos.get(program.glo)
        if found is None:
            layout = (self.vbo, "3f 3f 3f 2f", "in_position", "in_normal", "in_tangent", "in_uv")
            found = ctx.vertex_array(program, [layout], index_buffer=self.ibo, skip_errors=True)
            self._vaos[program.glo] = found
        return found

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        for obj in (self.vbo, self.ibo, self.normal_map):
            if obj is not None:
                obj.release()
