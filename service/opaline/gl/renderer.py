"""The renderer: owns one GL context and everything made in it.

Not thread-safe by design: a GL context is current on one thread, so a
Renderer is created, used and released on a single thread (the CLI's main
thread, or the service's render worker).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import moderngl
import numpy as np

from opaline.gl import passes, uniforms
from opaline.gl.buffers import (
    Cancelled,
    Frame,
    RenderBudgets,
    SceneGPU,
    Targets,
    read_bytes,
    read_float,
)
from opaline.gl.camera import model_matrix, place_key_light, view_projection
from opaline.gl.context import GLContext, create_context
from opaline.gl.detail import scene_for_size
from opaline.gl.probes import Probes
from opaline.gl.shaders import ProgramCache
from opaline.lru import BudgetLRU
from opaline.model.presets import Preset, get_preset
from opaline.model.request import Job

log = logging.getLogger(__name__)
NORMAL_MAP_UNIT = 1


class Renderer(Probes):
    """Draws jobs, and (through ``Probes``) MDF plots and BRDF probes, on its own headless context."""

    def __init__(self, backend: str | None = None, gl: GLContext | None = None,
                 budgets: RenderBudgets | None = None) -> None:
        self.gl = gl or create_context(backend)
        self.ctx = self.gl.ctx
        self.budgets = budgets = budgets or RenderBudgets()
        self._targets: BudgetLRU[tuple[int, int], Targets] = BudgetLRU(
            budgets.max_target_sizes, budgets.target_bytes, release=Targets.release)
        self._scenes: BudgetLRU[str, SceneGPU] = BudgetLRU(
            budgets.max_scenes, budgets.scene_bytes, release=SceneGPU.release)
        self._empty_vao: dict[int, moderngl.VertexArray] = {}
        self._flat_normal: moderngl.Texture | None = None
        self.programs = ProgramCache(self.ctx, budgets.max_programs, self._forget_program)

    # Resources

    def targets(self, size: tuple[int, int]) -> Targets:
        found = self._targets.get(size)
        if found is None:
            found = Targets(self.ctx, size)
            if not self._targets.put(size, found, found.nbytes):
                found.release()
                raise ValueError(f"{size[0]}×{size[1]} targets exceed the renderer's "
                                 f"budget of {self.budgets.target_bytes} bytes")
        return found

    def scene(self, preset: Preset) -> SceneGPU:
        key = preset.scene_key()
        found = self._scenes.get(key)
        if found is None:
            found = SceneGPU(self.ctx, preset)
            if not self._scenes.put(key, found, found.nbytes):
                found.release()
                raise ValueError(f"scene {preset.name} exceeds the renderer's budget of "
                                 f"{self.budgets.scene_bytes} bytes")
        return found

    def _forget_program(self, program: moderngl.Program) -> None:
        for scene in self._scenes.values():
            scene.drop_vao(program.glo)
        vao = self._empty_vao.pop(program.glo, None)
        if vao is not None:
            vao.release()

    def cache_stats(self) -> dict[str, int]:
        """Sizes and evictions of what this renderer keeps (reported by render workers)."""
        return {"programs": len(self.programs), "program_evictions": self.programs.evictions,
                "scenes": len(self._scenes), "scene_bytes": self._scenes.size_bytes,
                "scene_evictions": self._scenes.evictions, "targets": len(self._targets),
                "target_bytes": self._targets.size_bytes,
                "target_evictions": self._targets.evictions}

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

    read = staticmethod(read_float)

    # Scenes

    def render(self, job: Job, preset: Preset | None = None, all_features: bool = False,
               should_stop: Callable[[], bool] | None = None) -> Frame:
        """Draw a job. ``all_features`` compiles every optional feature in (with neutral
        values) instead of the scene's own variant: the benchmark's baseline.
        ``should_stop`` is asked between samples; when it says so, ``Cancelled`` is raised."""
        self.gl.make_current()
        preset = scene_for_size(preset or get_preset(job.preset), job.width, job.height)
        size = (job.width, job.height)
        samples = passes.plan(job.samples, size)
        drawn = self.targets(samples.target_size(size))
        channels = 4 if job.transparent else 3
        if samples.passes == samples.samples == 1 and job.format not in ("npy", "png16"):
            # One 8-bit sample: drawn and encoded in one pass, no resolve (rows bottom-up).
            self._draw_samples(job, preset, drawn, samples, all_features, should_stop, True)
            pixels = read_bytes(drawn.direct_fbo, size, channels)[::-1]
            return Frame(linear=None, display=None, pixels=np.ascontiguousarray(pixels))
        self._draw_samples(job, preset, drawn, samples, all_features, should_stop)
        # One pass is left in the sample target; more are summed in the accumulation target.
        if samples.passes == 1:
            fbo, source = drawn.sample_fbo, drawn.sample_tex
        else:
            fbo, source = drawn.accum_fbo, drawn.accum_tex
        if job.format == "npy":
            linear = passes.downsample(self.read(fbo, drawn.size), samples.factor)
            return Frame(linear=linear / np.float32(samples.samples), display=None)
        targets = self.targets(size)
        if job.format == "png16":
            self._resolve(job, preset, source, targets.display_fbo, samples)
            return Frame(linear=None, display=read_float(targets.display_fbo, size, flipped=True))
        self._resolve(job, preset, source, targets.display8_fbo, samples)
        return Frame(linear=None, display=None,
                     pixels=read_bytes(targets.display8_fbo, size, channels))

    def surface_defines(self, job: Job, preset: Preset) -> dict[str, int | bool]:
        defines = uniforms.material_defines(job.material, job.wavelengths, job.aa)
        defines["NORMAL_MAP"] = preset.normal_map is not None
        defines["TANGENT_CONCENTRIC"] = preset.tangents == "concentric"
        defines["LIGHT_COUNT"] = len(preset.lights)
        return defines

    def _draw_samples(self, job: Job, preset: Preset, targets: Targets,
                      samples: passes.SamplePlan, all_features: bool = False,
                      should_stop: Callable[[], bool] | None = None,
                      direct: bool = False) -> None:
        """``direct``: one sample into the 8-bit target, display-encoded by the surface."""
        ctx = self.ctx
        defines = self.surface_defines(job, preset)
        if direct:
            defines.update(DISPLAY=True, **self.tonemap_defines(job))
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
        values.update({
            "u_model": model.astype("f4"),
            "u_normal_matrix": np.linalg.inv(model[:3, :3]).T.astype("f4"),
            "u_view_proj": view_projection(preset.camera, width / height).astype("f4"),
            "u_eye": tuple(preset.camera.eye),
            "u_light_position": [
                (*light.position, 1.0 if light.type == "point" else 0.0) for light in lights],
            "u_light_irradiance": [tuple(light.irradiance) for light in lights],
            "u_ambient": tuple(preset.ambient),
            "u_aa_scale": samples.aa_scale,
            "u_exposure": job.exposure,
        })
        if normal_map is not None:
            values["u_normal_map"] = NORMAL_MAP_UNIT
            values["u_lod_bias"] = float(np.log2(samples.factor))
            # Bound once: the accumulate pass between samples binds unit 0 only.
            normal_map.use(location=NORMAL_MAP_UNIT)
        uniforms.apply(program, values)
        vao = scene.vao(ctx, program)
        offsets = samples.offsets
        multi = len(offsets) > 1
        if multi:
            accumulate = self.programs.get("accumulate.glsl")
            accumulate["u_sample"].value = 0
            targets.accum_fbo.use()
            targets.accum_fbo.clear(0.0, 0.0, 0.0, 0.0)
        for index, (dx, dy) in enumerate(offsets):
            if index and should_stop is not None and should_stop():
                raise Cancelled(f"stopped after {index} of {len(offsets)} samples")
            fbo = targets.direct_fbo if direct else targets.sample_fbo
            fbo.use()
            # Direct: the resolve's background (opaque) or nothing (transparent) is cleared to.
            opaque = direct and not job.transparent
            fbo.clear(*(preset.background if opaque else (0.0, 0.0, 0.0)), float(opaque),
                      depth=1.0)
            ctx.enable(moderngl.DEPTH_TEST)
            ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
            # Offsets are in image pixels; the target may be `factor` times larger.
            program["u_jitter"].value = (2.0 * samples.factor * dx / width,
                                         2.0 * samples.factor * dy / height)
            vao.render(moderngl.TRIANGLES)
            if multi:
                ctx.disable(moderngl.DEPTH_TEST)
                ctx.enable(moderngl.BLEND)
                ctx.blend_func = moderngl.ONE, moderngl.ONE
                targets.accum_fbo.use()
                targets.sample_tex.use(location=0)
                self.fullscreen(accumulate)
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)

    def _resolve(self, job: Job, preset: Preset, source: moderngl.Texture,
                 target: moderngl.Framebuffer, samples: passes.SamplePlan) -> None:
        defines = {**self.tonemap_defines(job), "TRANSPARENT": job.transparent,
                   "DOWNSAMPLE_2X": samples.factor == 2}
        program = self.programs.get("resolve.glsl", defines)
        target.use()
        source.use(location=0)
        uniforms.apply(program, {"u_accum": 0, "u_inv_samples": 1.0 / samples.samples,
                                 "u_exposure": job.exposure,
                                 "u_background": tuple(preset.background),
                                 "u_height": target.size[1]})
        self.fullscreen(program)

    @staticmethod
    def tonemap_defines(job: Job) -> dict[str, bool]:
        return {"TONEMAP_REINHARD": job.tonemap == "reinhard", "TONEMAP_ACES": job.tonemap == "aces"}

    def release(self) -> None:
        self.gl.make_current()
        for vao in self._empty_vao.values():
            vao.release()
        self._empty_vao.clear()
        self._scenes.clear()
        self._targets.clear()
        if self._flat_normal is not None:
            self._flat_normal.release()
        self.programs.release()
        self.gl.release()
