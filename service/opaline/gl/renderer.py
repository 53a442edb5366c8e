"""The renderer: owns one GL context and everything made in it.

Not thread-safe by design: a GL context is current on one thread, so a
Renderer is created, used and released on a single thread (the CLI's main
thread, or the service's render worker).

It is assembled from parts that each get what they use through their constructor:
``Resources`` (the context, targets, scenes, programs), the ``SurfacePass`` (with the
environment backgrounds), the ``Resolver`` and the ``Probes``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

import moderngl
import numpy as np

from opaline.gl import material_program, passes
from opaline.gl.background import Backgrounds
from opaline.gl.buffers import Cancelled as Cancelled  # re-exported: what workers catch
from opaline.gl.buffers import Frame, RenderBudgets, Targets, read_bytes, read_float
from opaline.gl.context import GLContext, create_context
from opaline.gl.environment_maps import EnvironmentMaps
from opaline.gl.probes import Probes
from opaline.gl.resolve import Resolver
from opaline.gl.resources import Resources
from opaline.gl.shaders import ProgramCache
from opaline.gl.surface_pass import ALL_FEATURES, DrawPlan, SurfacePass
from opaline.model.detail import scene_for_size
from opaline.model.params import Material
from opaline.model.presets import Preset, get_preset
from opaline.model.request import Job

log = logging.getLogger(__name__)


class Renderer:
    """Draws jobs, MDF plots and BRDF probes on its own headless context.

    ``environments_dir``: where user environment maps are looked up (the settings'
    ``environments_dir``; None: the built-in ones only); ``environment_paths``: a map may
    also be named by its path (the CLI's and the Python API's renderers, not a worker's)."""

    def __init__(self, backend: str | None = None, gl: GLContext | None = None,
                 budgets: RenderBudgets | None = None,
                 environments_dir: Path | None = None, environment_paths: bool = False) -> None:
        self.gl = gl or create_context(backend)
        self.budgets = budgets or RenderBudgets()
        self.resources = Resources(self.gl, self.budgets)
        self.environments = EnvironmentMaps(self.ctx, environments_dir, environment_paths)
        self.backgrounds = Backgrounds(self.ctx, self.resources.fullscreen, self.environments)
        self.surface = SurfacePass(self.resources, self.backgrounds)
        self.resolver = Resolver(self.resources)
        self.probes = Probes(self.resources)

    @property
    def ctx(self) -> moderngl.Context:
        return self.resources.ctx

    @property
    def programs(self) -> ProgramCache:
        return self.resources.programs

    def targets(self, size: tuple[int, int]) -> Targets:
        return self.resources.targets(size)

    def cache_stats(self) -> dict[str, int]:
        return self.resources.cache_stats()

    def mdf_plot(self, material: Material, size: int, wavelengths: int = 0,
                 aa: str = "none") -> np.ndarray:
        return self.probes.mdf_plot(material, size, wavelengths, aa)

    def probe(self, material: Material, n: np.ndarray, t: np.ndarray, l: np.ndarray,
              v: np.ndarray, wavelengths: int = 0) -> np.ndarray:
        return self.probes.probe(material, n, t, l, v, wavelengths)

    def surface_defines(self, job: Job, preset: Preset) -> dict[str, int | bool]:
        return material_program.surface_defines(job, preset)

    def render(self, job: Job, preset: Preset | None = None, all_features: bool = False,
               should_stop: Callable[[], bool] | None = None, brute: bool = False) -> Frame:
        """Draw a job. ``all_features`` compiles every optional feature in (with neutral
        values) instead of the scene's own variant: the benchmark's baseline. ``brute``
        reads an environment map unfiltered: the accuracy benchmark's converged reference.
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
        forced = ALL_FEATURES if all_features else ()
        if (samples.passes == samples.samples == 1 and job.format not in ("npy", "png16")
                and not job.environment_background):
            # One 8-bit sample: drawn and encoded in one pass, no resolve (rows bottom-up).
            plan = DrawPlan(samples, display=True, forced=forced, brute=brute)
            self.surface.draw(job, preset, drawn, plan, should_stop)
            pixels = read_bytes(drawn.direct_fbo, size, channels)[::-1]
            return Frame(linear=None, display=None, pixels=np.ascontiguousarray(pixels))
        self.surface.draw(job, preset, drawn, DrawPlan(samples, forced=forced, brute=brute),
                          should_stop)
        # One pass is left in the sample target; more are summed in the accumulation target.
        if samples.passes == 1:
            fbo, source = drawn.sample_fbo, drawn.sample_tex
        else:
            fbo, source = drawn.accum_fbo, drawn.accum_tex
        if job.format == "npy":
            linear = passes.downsample(read_float(fbo, drawn.size), samples.factor)
            return Frame(linear=in_space(linear / np.float32(samples.samples), job.color_space),
                         display=None)
        targets = self.targets(size)
        if job.format == "png16":
            self.resolver.resolve(job, preset, source, targets.display_fbo, samples)
            return Frame(linear=None, display=read_float(targets.display_fbo, size, flipped=True))
        self.resolver.resolve(job, preset, source, targets.display8_fbo, samples)
        return Frame(linear=None, display=None,
                     pixels=read_bytes(targets.display8_fbo, size, channels))

    def release(self) -> None:
        self.gl.make_current()
        self.environments.release()
        self.resources.release()
        self.gl.release()


def in_space(linear: np.ndarray, space: str) -> np.ndarray:
    """Linear sRGBA as linear RGBA in ``space``'s primaries (unmapped: a colour outside it
    keeps a channel below 0)."""
    if space == "srgb":
        return linear
    from opaline.model.color_space import from_srgb

    out = linear.copy()
    out[..., :3] = linear[..., :3] @ from_srgb(space).T.astype(np.float32)
    return out
