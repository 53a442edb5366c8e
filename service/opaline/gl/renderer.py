"""The renderer: owns one GL context and everything made in it.

Not thread-safe by design: a GL context is current on one thread, so a
Renderer is created, used and released on a single thread (the CLI's main
thread, or the service's render worker).
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from dataclasses import dataclass

import moderngl
import numpy as np

from opaline.gl import uniforms
from opaline.gl.camera import model_matrix, place_key_light, view_projection
from opaline.gl.context import GLContext, create_context
from opaline.gl.shaders import ProgramCache
from opaline.model.params import Material
from opaline.model.presets import Preset, build_assets, get_preset
from opaline.model.request import Job
from opaline.model.sampling import sample_offsets
from opaline.model.spectrum import wavelength_shift

log = logging.getLogger(__name__)
MAX_TARGET_SIZES = 4
NORMAL_MAP_UNIT = 1


@dataclass
class Frame:
    """A finished render. ``linear``: premultiplied linear RGBA; ``display``: sRGB RGBA in [0, 1]."""

    linear: np.ndarray | None
    display: np.ndarray | None


class Targets:
    """Framebuffers for one image size, kept and reused (DESIGN §8)."""

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


class Renderer:
    """Draws jobs, MDF plots and BRDF probes on its own headless context."""

    def __init__(self, backend: str | None = None, gl: GLContext | None = None) -> None:
        self.gl = gl or create_context(backend)
        self.ctx = self.gl.ctx
        self.programs = ProgramCache(self.ctx)
        self._targets: OrderedDict[tuple[int, int], Targets] = OrderedDict()
        self._scenes: dict[str, SceneGPU] = {}
        self._empty_vao: dict[int, moderngl.VertexArray] = {}
        self._flat_normal: moderngl.Texture | None = None

    # Resources

    def targets(self, size: tuple[int, int]) -> Targets:
        found = self._targets.pop(size, None) or Targets(self.ctx, size)
        self._targets[size] = found
        while len(self._targets) > MAX_TARGET_SIZES:
            _, old = self._targets.popitem(last=False)
            old.release()
        return found

    def scene(self, preset: Preset) -> SceneGPU:
        key = preset.scene_key()
        if key not in self._scenes:
            self._scenes[key] = SceneGPU(self.ctx, preset)
        return self._scenes[key]

    def flat_normal_map(self) -> moderngl.Texture:
        """A 1×1 map of the unperturbed normal, for the all-features baseline."""
        if self._flat_normal is None:
            data = np.array([0.0, 0.0, 1.0], dtype="f4").tobytes()
            self._flat_normal = self.ctx.texture((1, 1), 3, data, dtype="f4")
        return self._flat_normal

    def fullscreen(self, program: moderngl.Program) -> None:
        vao = self._empty_vao.get(program.glo)
        if vao is None:
            vao = self._empty_vao[program.glo] = self.ctx.vertex_array(program, [])
        vao.render(moderngl.TRIANGLES, vertices=3)

    @staticmethod
    def read(fbo: moderngl.Framebuffer, size: tuple[int, int], components: int = 4) -> np.ndarray:
        data = fbo.read(components=components, dtype="f4")
        image = np.frombuffer(data, dtype=np.float32).reshape(size[1], size[0], components)
        return np.ascontiguousarray(image[::-1])  # GL rows run bottom-up

    # Scenes

    def render(self, job: Job, preset: Preset | None = None, all_features: bool = False) -> Frame:
        """Draw a job. ``all_features`` compiles every optional feature in (with neutral
        values) instead of the scene's own variant: the benchmark's baseline."""
        self.gl.make_current()
        preset = preset or get_preset(job.preset)
        size = (job.width, job.height)
        targets = self.targets(size)
        offsets = sample_offsets(job.samples)
        self._draw_samples(job, preset, targets, offsets, all_features)
        # One sample is left in the sample target; more are summed in the accumulation target.
        if len(offsets) == 1:
            fbo, source = targets.sample_fbo, targets.sample_tex
        else:
            fbo, source = targets.accum_fbo, targets.accum_tex
        if job.format == "npy":
            linear = self.read(fbo, size) / np.float32(len(offsets))
            return Frame(linear=linear, display=None)
        self._resolve(job, preset, source, targets, len(offsets))
        return Frame(linear=None, display=self.read(targets.display_fbo, size))

    def surface_defines(self, job: Job, preset: Preset) -> dict[str, int | bool]:
        defines = uniforms.material_defines(job.material, job.wavelengths, job.aa)
        defines["NORMAL_MAP"] = preset.normal_map is not None
        defines["TANGENT_CONCENTRIC"] = preset.tangents == "concentric"
        defines["LIGHT_COUNT"] = len(preset.lights)
        return defines

    def _draw_samples(
        self,
        job: Job,
        preset: Preset,
        targets: Targets,
        offsets: np.ndarray,
        all_features: bool = False,
    ) -> None:
        ctx = self.ctx
        defines = self.surface_defines(job, preset)
        scene = self.scene(preset)
        normal_map = scene.normal_map
        if all_features:
            # AA stays as the job asks: it is a quality choice, not a scene feature.
            defines.update(DIFFUSE=True, FRESNEL=True, NORMAL_MAP=True)
            normal_map = normal_map or self.flat_normal_map()
        program = self.programs.get("surface.glsl", defines)
        width, height = targets.size
        lights = place_key_light(
            preset.lights, preset.camera.target, job.light_azimuth, job.light_elevation
        )
        model = model_matrix(preset.rotation_deg)
        values = uniforms.material_uniforms(job.material, job.wavelengths)
        values.update(
            {
                "u_model": model.astype("f4"),
                "u_normal_matrix": np.linalg.inv(model[:3, :3]).T.astype("f4"),
                "u_view_proj": view_projection(preset.camera, width / height).astype("f4"),
                "u_eye": tuple(preset.camera.eye),
                "u_light_position": [
                    (*light.position, 1.0 if light.type == "point" else 0.0) for light in lights
                ],
                "u_light_irradiance": [tuple(light.irradiance) for light in lights],
                "u_ambient": tuple(preset.ambient),
                "u_aa_scale": 1.0 / np.sqrt(len(offsets)),
            }
        )
        if normal_map is not None:
            values["u_normal_map"] = NORMAL_MAP_UNIT
            # Bound once: the accumulate pass between samples binds unit 0 only.
            normal_map.use(location=NORMAL_MAP_UNIT)
        uniforms.apply(program, values)
        vao = scene.vao(ctx, program)
        multi = len(offsets) > 1
        if multi:
            accumulate = self.programs.get("accumulate.glsl")
            accumulate["u_sample"].value = 0
            targets.accum_fbo.use()
            targets.accum_fbo.clear(0.0, 0.0, 0.0, 0.0)
        for index, (dx, dy) in enumerate(offsets):
            if job.wavelengths > 0 and multi:
                # Each supersample integrates the spectrum at its own points (spectrum.py).
                shift = wavelength_shift(index, len(offsets))
                uniforms.apply(program, uniforms.spectral_uniforms(job.material, job.wavelengths,
                                                                   shift))
            targets.sample_fbo.use()
            targets.sample_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            ctx.enable(moderngl.DEPTH_TEST)
            ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
            program["u_jitter"].value = (2.0 * dx / width, 2.0 * dy / height)
            vao.render(moderngl.TRIANGLES)
            if multi:
                ctx.disable(moderngl.DEPTH_TEST)
                ctx.enable(moderngl.BLEND)
                ctx.blend_func = moderngl.ONE, moderngl.ONE
                targets.accum_fbo.use()
                targets.sample_tex.use(location=0)
                self.fullscreen(accumulate)
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)

    def _resolve(
        self, job: Job, preset: Preset, source: moderngl.Texture, targets: Targets, count: int
    ) -> None:
        defines = {
            "TONEMAP_REINHARD": job.tonemap == "reinhard",
            "TONEMAP_ACES": job.tonemap == "aces",
            "TRANSPARENT": job.transparent,
        }
        program = self.programs.get("resolve.glsl", defines)
        targets.display_fbo.use()
        source.use(location=0)
        uniforms.apply(
            program,
            {
                "u_accum": 0,
                "u_inv_samples": 1.0 / count,
                "u_exposure": job.exposure,
                "u_background": tuple(preset.background),
            },
        )
        self.fullscreen(program)

    # Plots and probes

    def mdf_plot(
        self, material: Material, size: int, wavelengths: int = 0, aa: str = "none"
    ) -> np.ndarray:
        """The MDF over the projected half-vector disc, (size, size, 3) linear float32."""
        self.gl.make_current()
        defines = uniforms.mdf_defines(material, wavelengths, aa)
        defines["PRECISE_PHASE"] = self.gl.has_fp64
        program = self.programs.get("mdf_plot.glsl", defines)
        targets = self.targets((size, size))
        uniforms.apply(program, uniforms.material_uniforms(material, wavelengths))
        uniforms.apply(program, {"u_size": size, "u_aa_scale": 1.0})
        targets.display_fbo.use()
        self.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
        self.fullscreen(program)
        return self.read(targets.display_fbo, (size, size))[..., :3]

    def probe(
        self,
        material: Material,
        n: np.ndarray,
        t: np.ndarray,
        l: np.ndarray,
        v: np.ndarray,
        wavelengths: int = 0,
    ) -> np.ndarray:
        """Reflected radiance for each (n, t, l, v) case through the surface shading code."""
        self.gl.make_current()
        count = len(n)
        width = min(count, 256)
        height = -(-count // width)
        # aa stays "none" (AA_ANALYTIC false, so not compiled in): a probe has no pixel footprint.
        defines = uniforms.material_defines(material, wavelengths)
        defines["PRECISE_PHASE"] = self.gl.has_fp64
        program = self.programs.get("brdf_probe.glsl", defines)
        textures = []
        try:
            for unit, (name, data) in enumerate(
                (("u_normal", n), ("u_tangent", t), ("u_light", l), ("u_view", v))
            ):
                grid = np.zeros((height * width, 4), dtype="f4")
                grid[:count, :3] = data
                tex = self.ctx.texture((width, height), 4, grid.tobytes(), dtype="f4")
                textures.append(tex)
                tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
                tex.use(location=unit)
                program[name].value = unit
            uniforms.apply(program, uniforms.material_uniforms(material, wavelengths))
            targets = self.targets((width, height))
            targets.display_fbo.use()
            self.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
            self.fullscreen(program)
            image = self.read(targets.display_fbo, (width, height))
        finally:
            for tex in textures:
                tex.release()
        # Case i sits at GL row i // width; read() gave image order (top row first).
        return image[::-1].reshape(-1, 4)[:count, :3]

    def release(self) -> None:
        self.gl.make_current()
        for vao in self._empty_vao.values():
            vao.release()
        for scene in self._scenes.values():
            scene.release()
        for targets in self._targets.values():
            targets.release()
        if self._flat_normal is not None:
            self._flat_normal.release()
        self.programs.release()
        self.gl.release()
