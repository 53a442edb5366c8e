"""What a renderer keeps on the GPU between renders.

Framebuffers for each image size, and each preset's mesh and normal map,
made once in the renderer's context and released with it: moderngl does not
release attachments with their framebuffer, and Python's collector must not do
it from another thread (docs/design.md §10).
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from opaline.gl import physical
from opaline.gl.culling import Culling
from opaline.model import projection
from opaline.model.meshes import is_mesh
from opaline.model.presets import Preset, build_assets, build_thickness, build_weight

# Three RGBA float32 textures (sample, accumulation, float display), an RGBA8 display
# texture and a 32-bit depth buffer.
TARGET_BYTES_PER_PIXEL = 3 * 16 + 4 + 4


class Cancelled(Exception):
    """The render was stopped between samples because nobody waits for it any more."""


@dataclass(frozen=True)
class RenderBudgets:
    """What one renderer keeps for reuse, each an LRU bounded by count and bytes.

    The target budget must hold one 2048² set (about 218 MB) so that the largest
    allowed image can render; everything else is evicted oldest first."""

    max_programs: int = 64
    max_scenes: int = 16
    scene_bytes: int = 128 * 1024 * 1024
    max_target_sizes: int = 4
    target_bytes: int = 2048 * 2048 * TARGET_BYTES_PER_PIXEL


@dataclass
class Frame:
    """A finished render, top row first. ``linear``: premultiplied linear RGBA float32;
    ``display``: sRGB RGBA float32 in [0, 1] (for 16-bit output); ``pixels``: sRGB
    uint8, RGB or RGBA (for every 8-bit format). Exactly one is set."""

    linear: np.ndarray | None
    display: np.ndarray | None
    pixels: np.ndarray | None = None


def read_float(fbo: moderngl.Framebuffer, size: tuple[int, int], components: int = 4,
               flipped: bool = False) -> np.ndarray:
    """Float pixels, top row first. ``flipped``: the resolve pass already wrote them top
    row first (GL rows otherwise run bottom-up)."""
    data = fbo.read(components=components, dtype="f4")
    image = np.frombuffer(data, dtype=np.float32).reshape(size[1], size[0], components)
    return image.copy() if flipped else np.ascontiguousarray(image[::-1])


def read_bytes(fbo: moderngl.Framebuffer, size: tuple[int, int], components: int) -> np.ndarray:
    """The resolved 8-bit image as it lies in memory (the resolve wrote it top row first)."""
    data = fbo.read(components=components, alignment=1)
    return np.frombuffer(data, dtype=np.uint8).reshape(size[1], size[0], components)


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
        # 8-bit output resolves straight to bytes: GL quantises (round to nearest) and
        # the readback is a quarter of the float one, with no NumPy pass after it.
        self.display8_tex = ctx.texture(size, 4)
        self.display8_fbo = ctx.framebuffer([self.display8_tex])
        # One 8-bit sample drawn straight into the same bytes, with the depth buffer.
        self.direct_fbo = ctx.framebuffer([self.display8_tex], self.depth)

    @property
    def nbytes(self) -> int:
        return self.size[0] * self.size[1] * TARGET_BYTES_PER_PIXEL

    def release(self) -> None:
        for obj in (
            self.sample_fbo,
            self.accum_fbo,
            self.display_fbo,
            self.display8_fbo,
            self.direct_fbo,
            self.sample_tex,
            self.depth,
            self.accum_tex,
            self.display_tex,
            self.display8_tex,
        ):
            obj.release()


def bounding_sphere(positions: np.ndarray) -> tuple[np.ndarray, float]:
    points = positions.astype(np.float64)
    centre = (points.min(axis=0) + points.max(axis=0)) * 0.5
    return centre, float(np.linalg.norm(points - centre, axis=1).max())


class SceneGPU:
    """A preset's mesh and normal map, uploaded once."""

    def __init__(self, ctx: moderngl.Context, preset: Preset) -> None:
        mesh, normal_map = build_assets(preset)
        # A user's mesh is framed by the camera: a sphere about its box's centre holding
        # every vertex (tighter than the box's corners, so a torus fills the frame).
        self.bounds = bounding_sphere(mesh.positions) if is_mesh(preset) else None
        # A user's mesh without UVs takes the maps in object space: (origin, scale).
        self.projection: tuple[float, float, float, float] | None = None
        if is_mesh(preset) and projection.projects(preset.mesh_projection, mesh.uvs):
            origin, scale = projection.frame(mesh.positions)
            self.projection = (*origin, scale)
        self.vbo = ctx.buffer(mesh.interleaved().astype("f4").tobytes())
        self.ibo = ctx.buffer(mesh.indices.astype("u4").tobytes())
        # A sphere's v runs pole to pole: tiled, a pole's coarse mip level (its u squeezed
        # to a point) and its edge texels mixed in the other pole's rows, and a graded
        # field's thin top showed a dot of the thick bottom's colour.
        wraps_v = preset.geometry.kind != "sphere"
        self.normal_map = None
        if normal_map is not None:
            height, width = normal_map.shape[:2]
            # Rows flipped: the map's row 0 is v = 1 (image convention), GL's is v = 0.
            data = np.ascontiguousarray(normal_map[::-1].astype("f4"))
            self.normal_map = ctx.texture((width, height), 3, data.tobytes(), dtype="f4")
            self.normal_map.build_mipmaps()
            self.normal_map.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            self.normal_map.repeat_x, self.normal_map.repeat_y = True, wraps_v
        self.thickness_map = physical.thickness_texture(ctx, build_thickness(preset), wraps_v)
        self.weight_map = physical.thickness_texture(ctx, build_weight(preset), wraps_v)
        self.culling = Culling(mesh.positions, mesh.indices, planes=not is_mesh(preset))
        # Mipmaps add a third to a texture.
        self.nbytes = self.vbo.size + self.ibo.size + sum(
            tex.width * tex.height * tex.components * 4 * 4 // 3
            for tex in (self.normal_map, self.thickness_map, self.weight_map) if tex is not None)
        self._vaos: dict[int, moderngl.VertexArray] = {}

    def vao(self, ctx: moderngl.Context, program: moderngl.Program) -> moderngl.VertexArray:
        found = self._vaos.get(program.glo)
        if found is None:
            layout = (self.vbo, "3f 3f 3f 2f", "in_position", "in_normal", "in_tangent", "in_uv")
            found = ctx.vertex_array(program, [layout], index_buffer=self.ibo, skip_errors=True)
            self._vaos[program.glo] = found
        return found

    def drop_vao(self, program_glo: int) -> None:
        """Forget the vertex array made for a program that is being released."""
        vao = self._vaos.pop(program_glo, None)
        if vao is not None:
            vao.release()

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        for obj in (self.vbo, self.ibo, self.normal_map, self.thickness_map, self.weight_map):
            if obj is not None:
                obj.release()
