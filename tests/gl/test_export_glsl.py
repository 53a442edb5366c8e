"""The exported GLSL function compiles in a bare moderngl program (no Opaline code around
it) and renders the same image as Opaline's own shaders, for each shader variant."""

from __future__ import annotations

import re

import numpy as np
import pytest

from opaline.gl.export_glsl import export_glsl
from opaline.model.params import Material

pytestmark = pytest.mark.gl
SIZE = 48

VERTEX = """#version 330 core
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"""
MAIN = """
uniform sampler2D u_n, u_t, u_l, u_v;
out vec4 colour;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    colour = vec4(opaline_radiance(texelFetch(u_n, px, 0).xyz, texelFetch(u_t, px, 0).xyz,
                                   texelFetch(u_l, px, 0).xyz, texelFetch(u_v, px, 0).xyz), 1.0);
}
"""
VARIANTS = {
    "multipeak": (Material(), 0),
    "multipeak-spectral-diffuse-fresnel": (Material(kd=0.3, f0=0.04, mu_f=12.0), 8),
    "ashikhmin": (Material(mdf="ashikhmin", ex=300.0, ey=20.0, kd=0.1), 0),
    # The physical sources have int uniforms (grating orders) and their own libraries.
    "thin-film": (Material(mdf="ashikhmin", iridescence="thin-film", film_thickness_min=250.0,
                           film_thickness_max=250.0), 16),
    "grating-fast": (Material(mdf="ashikhmin", iridescence="grating", ex=2000.0, ey=2000.0), 0),
    # A film on a metal: complex arrays of n + ik (vec2) per wavelength or per channel.
    "conductor-spectral": (Material(iridescence="thin-film", substrate="conductor",
                                    metal="titanium", film_ior=2.4), 16),
    "conductor-fast": (Material(iridescence="thin-film", substrate="conductor", metal="gold",
                                film_ior=1.5, film_thickness_max=120.0), 0),
    # A partial film: the base's Fresnel and the weight compiled in (FILM_WEIGHT).
    "film-weight": (Material(mdf="ashikhmin", iridescence="thin-film", film_weight=0.4,
                             film_thickness_max=300.0), 0),
    "conductor-weight": (Material(iridescence="thin-film", substrate="conductor",
                                  metal="copper", film_weight=0.6), 16),
}


def sphere_cases() -> tuple[np.ndarray, ...]:
    """Per pixel of a SIZE² image of a unit sphere seen from +z: n, t (along the parallels),
    a light up and to the right, and the view; background pixels get a harmless case."""
    y, x = np.mgrid[1:-1:SIZE * 1j, -1:1:SIZE * 1j]
    inside = x * x + y * y < 0.98
    z = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, 1.0))
    n = np.where(inside[..., None], np.stack([x, y, z], -1), (0.0, 0.0, 1.0))
    t = np.stack([n[..., 2], np.zeros_like(x), -n[..., 0]], -1)
    t /= np.maximum(np.linalg.norm(t, axis=-1, keepdims=True), 1e-9)
    l = np.broadcast_to(np.array([0.5, 0.6, 0.62]) / np.linalg.norm([0.5, 0.6, 0.62]), n.shape)
    v = np.broadcast_to(np.array([0.0, 0.0, 1.0]), n.shape)
    return tuple(a.reshape(-1, 3) for a in (n, t, l, v))


def bare_render(ctx, source: str, cases) -> np.ndarray:
    program = ctx.program(vertex_shader=VERTEX, fragment_shader="#version 330 core\n" + source
                          + MAIN)
    textures, fbo, target = [], None, None
    try:
        for unit, (name, data) in enumerate(zip(("u_n", "u_t", "u_l", "u_v"), cases,
                                                strict=True)):
            grid = np.zeros((len(data), 4), "f4")
            grid[:, :3] = data
            # Row 0 of the texture is the image's bottom row, as gl_FragCoord counts.
            tex = ctx.texture((SIZE, SIZE), 4, grid.reshape(SIZE, SIZE, 4)[::-1].tobytes(),
                              dtype="f4")
            textures.append(tex)
            tex.use(location=unit)
            program[name].value = unit
        target = ctx.texture((SIZE, SIZE), 4, dtype="f4")
        fbo = ctx.framebuffer([target])
        fbo.use()
        ctx.vertex_array(program, []).render(vertices=3)
        image = np.frombuffer(fbo.read(components=4, dtype="f4"), "f4").reshape(SIZE, SIZE, 4)
        return image[::-1, :, :3].reshape(-1, 3)
    finally:
        for obj in (*textures, fbo, target, program):
            if obj is not None:
                obj.release()


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_exported_glsl_renders_what_opaline_renders(renderer, variant):
    material, wavelengths = VARIANTS[variant]
    source = export_glsl(material, wavelengths)
    # No uniform left to set: every declaration became a constant (comments may say "uniform").
    code = re.sub(r"//[^\n]*", "", source)
    assert re.search(r"\buniform\b", code) is None
    cases = sphere_cases()
    renderer.gl.make_current()
    exported = bare_render(renderer.ctx, source, cases)
    opaline = renderer.probe(material, *cases, wavelengths=wavelengths)
    assert np.all(np.isfinite(exported)) and exported.max() > 0.05
    scale = max(float(np.abs(opaline).max()), 1e-6)
    assert float(np.abs(exported - opaline).max()) / scale < 1e-3, variant


def test_exported_integer_tables_keep_every_bit():
    """The spectrum's packed table uses all 32 bits of each uint: exported as float literals
    it kept 24 (1073774600 became 1073774592), so the steps between its points moved."""
    from opaline.model import visible

    source = export_glsl(VARIANTS["grating-fast"][0], 0)
    line = next(x for x in source.splitlines() if x.startswith("const uvec3 u_visible_cumulative"))
    values = [int(x) for x in re.findall(r"(\d+)u\b", line.split("=", 1)[1])]
    expected = [x for point in visible.packed_cumulative_uniform() for x in point]
    assert values == expected
