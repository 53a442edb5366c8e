"""A tuned material as one self-contained GLSL function, for use outside Opaline.

    vec3 opaline_radiance(vec3 n, vec3 t, vec3 l, vec3 v)

returns the radiance reflected toward ``v`` per unit irradiance arriving from
``l`` (all unit vectors, world space; ``t`` the tangent the anisotropy follows,
orthogonalised against ``n`` inside), exactly the code Opaline's surface
shader runs for this material's variant: the shader library with its
``#include``s inlined, the variant's feature defines, and every material
uniform turned into a constant. GLSL 3.30 core (no fp64), no textures, no
uniforms: paste it into any fragment shader and multiply by your light.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping

from opaline import __version__
from opaline.gl import material_program
from opaline.gl.shaders import expand
from opaline.gl.uniforms import UniformValue
from opaline.model.params import Material

UNIFORM = re.compile(r"^\s*uniform\s+(\w+)\s+(\w+)\s*(\[\s*(\w+)\s*\])?\s*;")
GLSL_TYPES = {"real": "float", "real2": "vec2", "real3": "vec3"}
ENTRY = """
// The exported entry point.
vec3 opaline_radiance(vec3 n, vec3 t, vec3 l, vec3 v) {
    return vec3(reflected_radiance(material_params(), shading_frame(real3(n), real3(t)), l, v, -1.0));
}
"""


def _element_kind(kind: str) -> str:
    """The scalar type of a vector's (or matrix's) components; a scalar's own type."""
    for prefix, element in (("ivec", "int"), ("uvec", "uint"), ("bvec", "bool")):
        if kind.startswith(prefix):
            return element
    return "float" if kind.startswith(("vec", "mat")) else kind


def _scalar(kind: str, value: object) -> str:
    if not isinstance(value, int | float):
        raise TypeError(f"a {kind} uniform given {value!r}")
    if kind == "float":
        return repr(float(value))  # repr keeps every digit of the double
    # Integers as integers: a float literal keeps 24 bits, and the packed tables
    # (visible.packed_cumulative) use all 32. GLSL 3.30 converts no int to a uint.
    if kind == "int":
        return str(int(value))
    if kind == "uint":
        return f"{int(value)}u"
    if kind == "bool":
        return "true" if value else "false"
    raise TypeError(f"a {kind} uniform given the scalar {value!r}")


def _literal(kind: str, value: object) -> str:
    """A scalar or a vector (material_program gives each vector as a tuple) as GLSL."""
    kind = GLSL_TYPES.get(kind, kind)
    if isinstance(value, tuple):
        element = _element_kind(kind)
        return f"{kind}({', '.join(_scalar(element, x) for x in value)})"
    return _scalar(kind, value)


def _constant(match: re.Match[str], values: Mapping[str, UniformValue]) -> str:
    kind, name, array = match.group(1), match.group(2), match.group(3)
    if name not in values:
        return f"// (unused by this variant) {match.group(0).strip()}"
    value = values[name]
    if array:
        if not isinstance(value, list | tuple):
            raise TypeError(f"the {kind} array {name} given {value!r}")
        items = list(value)
        body = ", ".join(_literal(kind, v) for v in items)
        glsl = GLSL_TYPES.get(kind, kind)
        return f"const {kind} {name}[{len(items)}] = {glsl}[{len(items)}]({body});"
    if isinstance(value, list):
        value = value[0]
    return f"const {kind} {name} = {_literal(kind, value)};"


def export_glsl(material: Material, wavelengths: int = 0) -> str:
    """The GLSL source of ``opaline_radiance`` for this material (aa none: no pixel footprint)."""
    defines = material_program.material_defines(material, wavelengths)
    values = material_program.material_uniforms(material, wavelengths)
    values["u_aa_scale"] = 1.0
    lines = [
        f"// Opaline {__version__}: the multi-peak anisotropic microfacet model (Kang, Lee,",
        "// Cho 2014) for one material, as Opaline renders it. Parameters:",
        f"// {json.dumps(material.model_dump(mode='json'), sort_keys=True)}",
        f"// wavelengths={wavelengths} (0: the paper's RGB rotations)",
        "// Requires #version 330 core (or later) before this text.",
    ]
    for key in sorted(defines):
        value = defines[key]
        if value is not False:
            lines.append(f"#define {key}" if value is True else f"#define {key} {int(value)}")
    files: list[str] = []
    for line in expand("material_params.glsl", files) + expand("lib/reflectance.glsl", files):
        if line.startswith("#line"):
            continue
        match = UNIFORM.match(line)
        lines.append(_constant(match, values) if match else line)
    return "\n".join(lines) + "\n" + ENTRY
