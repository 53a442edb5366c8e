"""The surface pass: a job's samples drawn, one jittered pass each, into the sample
target (summed in the accumulation target) or, for one 8-bit sample, straight into the
display target.

What varies between draws is data, a ``DrawPlan``, made by the renderer: the sample
plan, whether the surface encodes for display itself, and which features are forced on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import moderngl
import numpy as np

from opaline.gl import (
    environment_light,
    heightfield,
    material_program,
    passes,
    physical,
    texture_units,
    uniforms,
)
from opaline.gl.background import Backgrounds
from opaline.gl.buffers import Cancelled, SceneGPU, Targets
from opaline.gl.lighting import light_uniforms
from opaline.gl.resolve import display_defines, display_uniforms
from opaline.gl.resources import Resources
from opaline.model import color_space
from opaline.model.camera import fit_matrix, model_matrix, view_camera, view_projection
from opaline.model.environment_light import reads_map
from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.model.spectrum import wavelength_shift

# The benchmark's baseline: every optional feature compiled in, with neutral values.
# AA stays as the job asks: it is a quality choice, not a scene feature.
ALL_FEATURES = ("DIFFUSE", "FRESNEL", "NORMAL_MAP")


@dataclass(frozen=True)
class DrawPlan:
    """``display``: one sample into the 8-bit target, display-encoded by the surface (no
    resolve); else linear samples into the float sample target. ``forced``: defines
    compiled in whatever the scene uses (a missing normal map is then the flat one).
    ``brute``: environment light read at full resolution, never filtered."""

    samples: passes.SamplePlan
    display: bool = False
    forced: tuple[str, ...] = ()
    brute: bool = False  # environment light at full resolution (the benchmark's reference)

    def target(self, targets: Targets) -> moderngl.Framebuffer:
        return targets.direct_fbo if self.display else targets.sample_fbo

    def clear_color(self, job: Job, preset: Preset) -> tuple[float, float, float, float]:
        """A direct draw clears to what the resolve composes over: the background (opaque)
        or nothing (transparent); linear samples clear to nothing, their alpha coverage."""
        opaque = self.display and not job.transparent
        if not opaque:
            return (0.0, 0.0, 0.0, 0.0)
        red, green, blue = (float(v) for v in
                            color_space.display_background(preset.background, job.color_space))
        return (red, green, blue, 1.0)


@dataclass(frozen=True)
class Placement:
    """Where the object and the camera are, for one target's aspect."""

    model: np.ndarray
    eye: tuple[float, ...]
    view_proj: np.ndarray


def place(job: Job, preset: Preset, scene: SceneGPU, size: tuple[int, int]) -> Placement:
    model = model_matrix(preset.rotation_deg)
    if scene.bounds is not None:
        model = fit_matrix(scene.bounds, preset.camera.target) @ model
    aspect = size[0] / size[1]
    camera = view_camera(preset.camera, aspect, scene.bounds is not None,
                         job.camera_azimuth, job.camera_elevation, job.camera_distance)
    return Placement(model, tuple(camera.eye), view_projection(camera, aspect))


class SurfacePass:
    def __init__(self, resources: Resources, backgrounds: Backgrounds) -> None:
        self.resources = resources
        self.backgrounds = backgrounds

    def draw(self, job: Job, preset: Preset, targets: Targets, plan: DrawPlan,
             should_stop: Callable[[], bool] | None = None) -> None:
        scene = self.resources.scene(preset)
        where = place(job, preset, scene, targets.size)
        front_face = scene.culling.front_face(where.model, where.view_proj)
        # Backs are shaded as fronts where one can be seen: not where culled, and on a
        # built-in mesh only if this view sees one (a user's mesh not culled may).
        two_sided = front_face is None and scene.culling.shows_back(where.model, where.eye)
        program = self._program(job, preset, scene, plan, where, two_sided)
        background = self.backgrounds.prepare(self.resources.programs, job, where.view_proj,
                                              targets.size)
        self._samples(job, preset, targets, plan, program, scene.vao(self.resources.ctx, program),
                      background, front_face, should_stop)

    def _program(self, job: Job, preset: Preset, scene: SceneGPU, plan: DrawPlan,
                 where: Placement, two_sided: bool) -> moderngl.Program:
        """The surface variant for this job and plan, its uniforms set and textures bound."""
        defines = material_program.surface_defines(job, preset, plan.brute)
        if two_sided:
            defines["TWO_SIDED"] = True
        if scene.projection is not None:
            defines["OBJECT_PROJECTION"] = True
        if plan.display:
            defines.update(DISPLAY=True, **display_defines(job))
        defines.update(dict.fromkeys(plan.forced, True))
        lights = self._light(job, preset, plan, defines)
        program = self.resources.programs.get("surface.glsl", defines)
        normal_matrix = np.linalg.inv(where.model[:3, :3]).T
        normal_matrix /= abs(np.linalg.det(normal_matrix)) ** (1.0 / 3.0)  # unit normals stay ~unit
        values = material_program.material_uniforms(job.material, job.wavelengths)
        values.update({
            "u_model": where.model.astype("f4"),
            "u_normal_matrix": normal_matrix.astype("f4"),
            "u_view_proj": where.view_proj.astype("f4"),
            "u_eye": where.eye,
            **lights,
            # An environment is the whole light: its lights carry the map's diffuse part too.
            "u_ambient": (0.0, 0.0, 0.0) if job.environment else tuple(preset.ambient),
            "u_aa_scale": plan.samples.aa_scale,
            "u_exposure": job.exposure,
            **display_uniforms(job),
            **heightfield.uniforms(preset),
            "u_projection": scene.projection or (0.0, 0.0, 0.0, 1.0),
        })
        values.update(self._textures(job, preset, scene, plan, defines))
        uniforms.apply(program, values)
        return program

    def _light(self, job: Job, preset: Preset, plan: DrawPlan,
               defines: dict[str, int | bool]) -> uniforms.Uniforms:
        """The environment's map (and its defines), or the lights: the preset's, or the
        environment's by median cut."""
        if reads_map(job) or (plan.brute and job.environment is not None):
            assert job.environment is not None
            environment = self.backgrounds.maps.get(job.environment)
            defines.update(environment_light.defines(job, plan.samples, environment, plan.brute))
            environment.texture.use(location=texture_units.ENVIRONMENT)
            return environment_light.uniforms(job, plan.samples, environment, plan.brute)
        lights = light_uniforms(job, preset, self.backgrounds.maps)
        defines["LIGHT_COUNT"] = len(lights["u_light_position"])
        return dict(lights)

    def _textures(self, job: Job, preset: Preset, scene: SceneGPU, plan: DrawPlan,
                  defines: dict[str, int | bool]) -> uniforms.Uniforms:
        """Binds the variant's textures (once: the accumulate pass binds unit 0 only) and
        gives the uniforms that go with them."""
        values: uniforms.Uniforms = {}
        normal_map = scene.normal_map
        if normal_map is None and "NORMAL_MAP" in plan.forced:
            normal_map = self.resources.flat_normal_map()
        if normal_map is not None:
            values["u_normal_map"] = texture_units.NORMAL_MAP
            values["u_lod_bias"] = float(np.log2(plan.samples.factor))
            normal_map.use(location=texture_units.NORMAL_MAP)
        if defines.get("TRANSMISSION"):
            values["u_backdrop"] = physical.backdrop_radiance(
                preset.background, job.tonemap, job.exposure, job.color_space)
        if defines.get("THICKNESS_MAP"):
            values["u_thickness_map"] = texture_units.THICKNESS_MAP
            assert scene.thickness_map is not None  # the define follows the preset's map
            scene.thickness_map.use(location=texture_units.THICKNESS_MAP)
        if defines.get("FILM_WEIGHT_MAP"):
            values["u_weight_map"] = texture_units.WEIGHT_MAP
            assert scene.weight_map is not None  # the define follows the preset's map
            scene.weight_map.use(location=texture_units.WEIGHT_MAP)
        return values

    def _samples(self, job: Job, preset: Preset, targets: Targets, plan: DrawPlan,
                 program: moderngl.Program, vao: moderngl.VertexArray,
                 background: Callable[[tuple[float, float]], None] | None,
                 front_face: str | None, should_stop: Callable[[], bool] | None) -> None:
        """One pass per offset; more than one are summed into the accumulation target."""
        ctx = self.resources.ctx
        samples = plan.samples
        width, height = targets.size
        offsets = samples.offsets
        accumulate = self._start_accumulation(targets) if len(offsets) > 1 else None
        for index, (dx, dy) in enumerate(offsets):
            if index and should_stop is not None and should_stop():
                raise Cancelled(f"stopped after {index} of {len(offsets)} samples")
            if job.wavelengths > 0 and accumulate is not None:
                # Each supersample integrates the spectrum at its own points (spectrum.py).
                shift = wavelength_shift(index, len(offsets))
                uniforms.apply(program, material_program.spectral_uniforms(
                    job.material, job.wavelengths, shift))
            fbo = plan.target(targets)
            fbo.use()
            fbo.clear(*plan.clear_color(job, preset), depth=1.0)
            # Offsets are in image pixels; the target may be `factor` times larger.
            jitter = (2.0 * samples.factor * dx / width, 2.0 * samples.factor * dy / height)
            if background is not None:
                background(jitter)
            ctx.enable(moderngl.DEPTH_TEST)
            ctx.disable(moderngl.BLEND)
            if front_face is not None:  # only the surface: full-screen passes are not culled
                ctx.front_face = front_face
                ctx.enable(moderngl.CULL_FACE)
            program["u_jitter"] = jitter
            if "u_env_pass" in program:
                program["u_env_pass"] = index
            vao.render(moderngl.TRIANGLES)
            ctx.disable(moderngl.CULL_FACE)
            if accumulate is not None:
                self._accumulate(targets, accumulate)
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)

    def _start_accumulation(self, targets: Targets) -> moderngl.Program:
        accumulate = self.resources.programs.get("accumulate.glsl")
        accumulate["u_sample"] = 0
        targets.accum_fbo.use()
        targets.accum_fbo.clear(0.0, 0.0, 0.0, 0.0)
        return accumulate

    def _accumulate(self, targets: Targets, accumulate: moderngl.Program) -> None:
        """Adds the sample just drawn into the accumulation target."""
        ctx = self.resources.ctx
        ctx.disable(moderngl.DEPTH_TEST)
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.ONE, moderngl.ONE
        targets.accum_fbo.use()
        targets.sample_tex.use(location=0)
        self.resources.fullscreen(accumulate)
