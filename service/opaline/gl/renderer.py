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

from opaline.gl import heightfield, passes, physical, uniforms
from opaline.gl.background import Backgrounds
from opaline.gl.buffers import (
    Cancelled,
    Frame,
    RenderBudgets,
    SceneGPU,
    Targets,
    read_bytes,
    read_float,
)
from opaline.gl.context import GLContext, create_context
from opaline.gl.kept import Kept
from opaline.gl.lighting import light_uniforms
from opaline.gl.probes import Probes
from opaline.gl.resolve import Resolve
from opaline.gl.shaders import ProgramCache
from opaline.gl.variants import surface_defines
from opaline.lru import BudgetLRU
from opaline.model.camera import (
    fit_matrix,
    model_matrix,
    view_camera,
    view_projection,
)
from opaline.model.detail import scene_for_size
from opaline.model.presets import Preset, get_preset
from opaline.model.request import Job
from opaline.model.spectrum import wavelength_shift

log = logging.getLogger(__name__)
NORMAL_MAP_UNIT = 1


class Renderer(Kept, Probes, Resolve):
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
        self.backgrounds = Backgrounds(self.ctx, self.fullscreen)

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
        # Spectral supersamples each integrate at their own wavelengths (one pass each), and
        # an environment background is drawn per pass: those keep one sample a pass.
        per_pass = job.wavelengths > 0 or bool(job.environment_background)
        samples = passes.plan(job.samples, size, grid=not per_pass)
        drawn = self.targets(samples.target_size(size))
        channels = 4 if job.transparent else 3
        if (samples.passes == samples.samples == 1 and job.format not in ("npy", "png16")
                and not job.environment_background):
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
        return surface_defines(job, preset)

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
        width, height = targets.size
        lights = light_uniforms(job, preset)
        defines["LIGHT_COUNT"] = len(lights["u_light_position"])
        program = self.programs.get("surface.glsl", defines)
        model = model_matrix(preset.rotation_deg)
        if scene.bounds is not None:
            model = fit_matrix(scene.bounds, preset.camera.target) @ model
        camera = view_camera(preset.camera, width / height, scene.bounds is not None,
                             job.camera_azimuth, job.camera_elevation, job.camera_distance)
        view_proj = view_projection(camera, width / height)
        background = self.backgrounds.prepare(self.programs, job, view_proj, targets.size)
        normal_matrix = np.linalg.inv(model[:3, :3]).T
        normal_matrix /= abs(np.linalg.det(normal_matrix)) ** (1.0 / 3.0)  # unit normals stay ~unit
        values = uniforms.material_uniforms(job.material, job.wavelengths)
        values.update({
            "u_model": model.astype("f4"),
            "u_normal_matrix": normal_matrix.astype("f4"),
            "u_view_proj": view_proj.astype("f4"),
            "u_eye": tuple(camera.eye),
            **lights,
            "u_ambient": tuple(preset.ambient),
            "u_aa_scale": samples.aa_scale,
            "u_exposure": job.exposure,
            **heightfield.uniforms(preset),
        })
        if normal_map is not None:
            values["u_normal_map"] = NORMAL_MAP_UNIT
            values["u_lod_bias"] = float(np.log2(samples.factor))
            # Bound once: the accumulate pass between samples binds unit 0 only.
            normal_map.use(location=NORMAL_MAP_UNIT)
        if defines.get("TRANSMISSION"):
            values["u_backdrop"] = physical.backdrop_radiance(
                preset.background, job.tonemap, job.exposure)
        if defines.get("THICKNESS_MAP"):
            values["u_thickness_map"] = physical.THICKNESS_UNIT
            scene.thickness_map.use(location=physical.THICKNESS_UNIT)
        uniforms.apply(program, values)
        vao = scene.vao(ctx, program)
        front_face = scene.culling.front_face(model, view_proj)
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
            if job.wavelengths > 0 and multi:
                # Each supersample integrates the spectrum at its own points (spectrum.py).
                shift = wavelength_shift(index, len(offsets))
                uniforms.apply(program, uniforms.spectral_uniforms(job.material, job.wavelengths,
                                                                   shift))
            fbo = targets.direct_fbo if direct else targets.sample_fbo
            fbo.use()
            # Direct: the resolve's background (opaque) or nothing (transparent) is cleared to.
            opaque = direct and not job.transparent
            fbo.clear(*(preset.background if opaque else (0.0, 0.0, 0.0)), float(opaque),
                      depth=1.0)
            # Offsets are in image pixels; the target may be `factor` times larger.
            jitter = (2.0 * samples.factor * dx / width, 2.0 * samples.factor * dy / height)
            if background is not None:
                background(jitter)
            ctx.enable(moderngl.DEPTH_TEST)
            ctx.disable(moderngl.BLEND)
            if front_face is not None:  # only the surface: full-screen passes are not culled
                ctx.front_face = front_face
                ctx.enable(moderngl.CULL_FACE)
            program["u_jitter"].value = jitter
            vao.render(moderngl.TRIANGLES)
            ctx.disable(moderngl.CULL_FACE)
            if multi:
                ctx.disable(moderngl.DEPTH_TEST)
                ctx.enable(moderngl.BLEND)
                ctx.blend_func = moderngl.ONE, moderngl.ONE
                targets.accum_fbo.use()
                targets.sample_tex.use(location=0)
                self.fullscreen(accumulate)
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)

    def release(self) -> None:
        self.gl.make_current()
        for vao in self._empty_vao.values():
            vao.release()
        self._empty_vao.clear()
        self._scenes.clear()
        self._targets.clear()
        self.backgrounds.release()
        if self._flat_normal is not None:
            self._flat_normal.release()
        self.programs.release()
        self.gl.release()
