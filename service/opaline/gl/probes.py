"""Diagnostic draws: the MDF plot over the half-vector disc, and the BRDF probe.

Both run the same GLSL library as the surface shader, outside any scene: the
plot draws the paper's Figs. 2, 3, 6 and 7 (docs/design.md §3), and the probe
evaluates the reflectance at given (n, t, l, v) so that tests can hold it
against the float64 reference case by case.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import moderngl
import numpy as np

from opaline.gl import environment_light, material_program, texture_units, uniforms
from opaline.gl.buffers import read_float
from opaline.gl.resources import Resources
from opaline.model.envelope import band_mean, cell_side
from opaline.model.params import Material

# glsl/lobe_probe.glsl's modes: what each case evaluates.
LOBE_MODES = {"ashikhmin": 0, "disc": 1, "mixture": 2, "irradiance": 3, "specular": 4,
              "sequence": 5, "envelope": 6, "band_cell": 7, "coat": 8, "lookup": 9}



def case_grid(count: int) -> tuple[int, int]:
    """The probe target's size for ``count`` cases, one a pixel, rows of at most 256."""
    width = min(count, 256)
    return width, -(-count // width)


@contextmanager
def case_textures(res: Resources, cases: Sequence[np.ndarray]) -> Iterator[None]:
    """Each (count, 3) input as a float texture on units 0, 1, ...: case i at pixel
    (i % width, i // width), read with texelFetch; released on the way out."""
    count = len(cases[0])
    width, height = case_grid(count)
    textures = []
    try:
        for unit, data in enumerate(cases):
            grid = np.zeros((height * width, 4), dtype="f4")
            grid[:count, :3] = data
            textures.append(res.ctx.texture((width, height), 4, grid.tobytes(), dtype="f4"))
            textures[-1].filter = (moderngl.NEAREST, moderngl.NEAREST)
            textures[-1].use(location=unit)
        yield
    finally:
        for texture in textures:
            texture.release()


def draw_cases(res: Resources, program: moderngl.Program, count: int) -> np.ndarray:
    """One full-screen draw of a probe program: (count, 4), case order."""
    width, height = case_grid(count)
    targets = res.targets((width, height))
    targets.display_fbo.use()
    res.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
    res.fullscreen(program)
    image = read_float(targets.display_fbo, (width, height))
    # Case i sits at GL row i // width; read() gave image order (top row first).
    result: np.ndarray = image[::-1].reshape(-1, 4)[:count]
    return result

class Probes:
    """The plot and the probe, drawn with the renderer's resources (the renderer hands
    its callers these methods)."""

    def __init__(self, resources: Resources) -> None:
        self.resources = resources

    def mdf_plot(
        self, material: Material, size: int, wavelengths: int = 0, aa: str = "none"
    ) -> np.ndarray:
        """The MDF over the projected half-vector disc, (size, size, 3) linear float32."""
        res = self.resources
        res.gl.make_current()
        defines = material_program.plot_defines(material, wavelengths, aa)
        defines["PRECISE_PHASE"] = res.gl.has_fp64
        program = res.programs.get("mdf_plot.glsl", defines)
        targets = res.targets((size, size))
        uniforms.apply(program, material_program.material_uniforms(material, wavelengths))
        uniforms.apply(program, {"u_size": size, "u_aa_scale": 1.0})
        targets.display_fbo.use()
        res.ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
        res.fullscreen(program)
        return read_float(targets.display_fbo, (size, size))[..., :3]

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
        res = self.resources
        res.gl.make_current()
        # aa stays "none" (AA_ANALYTIC false, so not compiled in): a probe has no pixel footprint.
        defines = material_program.material_defines(material, wavelengths)
        defines["PRECISE_PHASE"] = res.gl.has_fp64
        program = res.programs.get("brdf_probe.glsl", defines)
        with case_textures(res, (n, t, l, v)):
            for unit, name in enumerate(("u_normal", "u_tangent", "u_light", "u_view")):
                program[name] = unit
            uniforms.apply(program, material_program.material_uniforms(material, wavelengths))
            return draw_cases(res, program, len(n))[:, :3]

    def triplanar(self, q: np.ndarray, n: np.ndarray, texels: np.ndarray) -> np.ndarray:
        """glsl/lib/triplanar.glsl for each (projection coordinate, object normal) case, on
        an RGBA float map (row 0 at v = 0): (count, 4), blended normal and scalar."""
        res = self.resources
        res.gl.make_current()
        program = res.programs.get("triplanar_probe.glsl", {})
        program["u_position"], program["u_normal"] = 0, 1
        rows, cols = texels.shape[:2]
        texture = res.ctx.texture((cols, rows), 4, texels.astype("f4").tobytes(), dtype="f4")
        try:
            with case_textures(res, (q, n)):
                texture.repeat_x = texture.repeat_y = True
                texture.use(location=2)
                program["u_map"] = 2
                return draw_cases(res, program, len(q))
        finally:
            texture.release()

    def lobe(self, material: Material, mode: str, cases: tuple[np.ndarray, ...],
             environment: tuple[moderngl.Texture, np.ndarray] | None = None,
             rotation: float = 0.0, intensity: float = 1.0, samples: int = 1,
             passes: int = 1, brute: bool = True, wavelengths: int = 0,
             rgb_lobes: bool = False, grating_reads: int = 0) -> np.ndarray:
        """glsl/lobe_probe.glsl for each case (up to three (count, 3) inputs, see its
        modes in ``LOBE_MODES``): (passes, count, 4), pass k continuing the pixel's
        sequence as the surface's passes do. ``environment``: the map's texture and
        irradiance coefficients (gl/background.py's), ``samples`` a pass's lobe samples,
        ``brute`` level 0 always (else the filtered read, for ``samples · passes`` in all);
        ``wavelengths`` > 0: the spectral variant, split into envelope and bands where the
        lobe is the multi-peak one (model/envelope.py); ``rgb_lobes``: the rotation
        source's map samples in the paper's three channels; ``grating_reads``: a
        grating's orders read along their curve, that many reads a pass (brute: level 0)."""
        res = self.resources
        res.gl.make_current()
        coloured_by_rotation = material.iridescence == "rotation"
        if rgb_lobes and not (coloured_by_rotation and material.mdf == "ashikhmin"):
            raise ValueError("rgb_lobes: only the rotation source's Ashikhmin-Shirley lobes")
        defines = {**material_program.material_defines(material, wavelengths,
                                                       orders_read=grating_reads > 0),
                   "ENV_SAMPLES": samples, "ENV_BRUTE": brute, "COAT_SAMPLES": samples,
                   # As the renderer decides (gl/environment_light.py), for one case.
                   "ENV_ENVELOPE": (coloured_by_rotation and material.mdf == "multipeak"
                                    and wavelengths > 0 and not brute),
                   "ENV_RGB_LOBES": rgb_lobes,
                   "ENV_GRATING_ORDERS": grating_reads > 0,
                   "ENV_GRATING_READS": grating_reads or False}
        program = res.programs.get("lobe_probe.glsl", defines)
        values = material_program.material_uniforms(material, wavelengths)
        values.update({"u_mode": LOBE_MODES[mode], "u_env_rotation": rotation,
                       "u_env_intensity": intensity, "u_env_total": float(samples * passes),
                       # The coat's reads: as many a pass as the lobe's.
                       "u_env_coat_total": float(samples * passes),
                       "u_env_lobe_rotation": environment_light.lobe_rotations(material),
                       "u_env_band_mean": band_mean(material.mu_f, material.alpha,
                                                    material.beta, cell_side(passes))})
        if environment is not None:
            texture, sh = environment
            texture.use(location=texture_units.ENVIRONMENT)
            values.update(environment_light.map_uniforms(texture, sh))
        if grating_reads:
            values.update(environment_light.grating_uniforms())
        values.update({"u_case_" + "abc"[unit]: unit for unit in range(len(cases))})
        results = []
        with case_textures(res, cases):
            uniforms.apply(program, values)
            for index in range(passes):
                if "u_env_pass" in program:
                    program["u_env_pass"] = index
                results.append(draw_cases(res, program, len(cases[0])))
        return np.stack(results)
