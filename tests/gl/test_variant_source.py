"""The source a program variant compiles (opaline.gl.variant_source): the digest the
accuracy table stamps each preset with changes with what a variant compiles, and only
with that."""

from __future__ import annotations

import pytest

from opaline.gl import shaders
from opaline.gl.shaders import ShaderError, compose
from opaline.gl.variant_source import (
    active_lines,
    evaluate,
    variant_digest,
    variant_key,
    variant_label,
    variant_text,
)

# cd-rom-ashikhmin's surface under an environment map (the rotation source's lobes), and
# cd-rom-grating's (a grating's orders): two variants that share most of their libraries.
ROTATION = ("surface.glsl", (("DIFFUSE", 1), ("ENVIRONMENT_MAP", 1), ("ENV_QUAD_MEAN", 1),
                             ("ENV_RGB_LOBES", 1), ("ENV_SAMPLES", 6), ("LIGHT_COUNT", 1),
                             ("MDF_ASHIKHMIN", 1), ("TANGENT_CONCENTRIC", 1),
                             ("WAVELENGTHS", 16)))
GRATING = ("surface.glsl", (("BESSEL_TERMS", 9), ("DIFFUSE", 1), ("ENVIRONMENT_MAP", 1),
                            ("ENV_GRATING_ORDERS", 1), ("ENV_GRATING_READS", 3),
                            ("ENV_SAMPLES", 3), ("FRESNEL", 1),
                            ("GRATING_ORDERS", 3), ("IRIDESCENCE_GRATING", 1),
                            ("LIGHT_COUNT", 1), ("MDF_ASHIKHMIN", 1), ("TANGENT_CONCENTRIC", 1),
                            ("WAVELENGTHS", 16)))


def digests() -> tuple[str, str]:
    shaders.read_source.cache_clear()
    return variant_digest([ROTATION]), variant_digest([GRATING])


def edit(path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f"{path.name} no longer has {old!r}: the test needs another edit"
    path.write_text(text.replace(old, new, 1))


@pytest.mark.parametrize(("expression", "macros", "expected"), [
    ("defined(A) && !defined(B)", {"A": 1}, True),
    ("!defined(A) && !defined(B) && !defined(C)", {"C": 1}, False),
    ("WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)", {"WAVELENGTHS": 16}, False),
    ("(WAVELENGTHS == 0 || defined(G)) && defined(H)", {"G": 1, "H": 1}, True),
    ("ENV_SAMPLES % 3 == 0", {"ENV_SAMPLES": 6}, True),
    ("ENV_SAMPLES % 3 == 0", {"ENV_SAMPLES": 4}, False),
    ("ENV_SAMPLES % 3 == 0", {}, True),  # an undefined name is 0, as in C
    ("GRATING_ORDERS >= 4", {"GRATING_ORDERS": 3}, False),
    ("BESSEL_TERMS > 16", {"BESSEL_TERMS": 17}, True),
    ("A != 2", {"A": 2}, False),
])
def test_conditions_evaluate_as_the_c_preprocessor_does(expression, macros, expected):
    assert evaluate(expression, macros) is expected


def test_nested_branches_and_include_guards():
    source = "\n".join([
        "#ifndef GUARD", "#define GUARD", "#define N 2", "a;  // comment", "",
        "#if N > 1", "b;", "#ifdef X", "c;", "#else", "d;", "#endif", "#elif N > 0", "e;",
        "#else", "f;", "#endif", "#ifdef X", "#if 1", "g;", "#endif", "#else", "h;", "#endif",
        "#endif", "#ifndef GUARD", "i;", "#endif"])
    assert active_lines(source) == ["#define GUARD", "#define N 2", "a;", "b;", "d;", "h;"]


@pytest.mark.parametrize(("expression", "macros"), [
    ("foo(1)", {}), ("A &&", {"A": 1}),
    # where C and a textual translation to Python disagree: refused, not guessed
    ("!A == B", {"A": 2, "B": 1}), ("!A + 1", {"A": 0}), ("3 > 2 > 1", {}),
    ("1 & 2 == 2", {}), ("-7 / 2 == -3", {}), ("-7 % 2 == -1", {}),
    ("BINS > 8", {"BINS": None}),  # #define BINS WAVELENGTHS: not an integer
])
def test_an_expression_outside_the_subset_is_an_error(expression, macros):
    with pytest.raises(ShaderError, match="subset"):
        evaluate(expression, macros)


def test_directives_outside_the_subset_or_unclosed_branches_are_errors():
    with pytest.raises(ShaderError, match="unterminated"):
        active_lines("#ifdef A\na;\n")
    with pytest.raises(ShaderError, match="block comments"):
        active_lines("a; /* b */\n")
    with pytest.raises(ShaderError, match="subset"):
        active_lines("#define F(x) x\n#if F > 0\n#endif\n")


def test_undef_and_an_enabled_extension_are_read():
    """The driver defines an extension's macro where it has it (llvmpipe has every one
    compose enables): its branch is the one compiled."""
    source = "\n".join(["#extension GL_ARB_derivative_control : enable", "#define A",
                        "#undef A", "#ifdef GL_ARB_derivative_control", "fine;", "#else",
                        "coarse;", "#endif", "#ifdef A", "a;", "#endif"])
    assert active_lines(source)[1:] == ["#define A", "#undef A", "fine;"]


def test_a_comment_or_a_skipped_branch_leaves_a_variants_digest(glsl_copy):
    """sources_digest changes with any edit; a variant's digest only with its own code."""
    rotation, grating = digests()
    light = glsl_copy / "lib" / "environment_light.glsl"
    edit(light, "// Into the map's own frame", "// Into the map frame\n// and a new line")
    assert digests() == (rotation, grating)
    # Each variant skips the other's code: the grating's orders and the three lobes.
    edit(glsl_copy / "lib" / "environment_grating.glsl", "float k = l.z + nv;",
         "float k = nv + l.z;")
    rotation_now, grating_now = digests()
    assert rotation_now == rotation and grating_now != grating
    edit(light, "    int c = int(min(u.z * 3.0, 2.0));", "    int c = int(min(u.z * 3.0, 1.0));")
    changed = digests()
    assert changed[0] != rotation and changed[1] == grating_now
    # The quad's mean takes the fine derivatives where the extension is there (llvmpipe).
    edit(light, "#define QUAD_DX dFdxFine", "#define QUAD_DX dFdxCoarse")
    assert digests()[0] != changed[0]


def test_an_edit_to_code_every_variant_compiles_changes_each_digest(glsl_copy):
    rotation, grating = digests()
    edit(glsl_copy / "lib" / "environment_light.glsl", "* env.intensity;",
         "* env.intensity * 1.0;")
    changed = digests()
    assert changed[0] != rotation and changed[1] != grating


def test_labels_name_the_variant():
    assert variant_key(variant_label(GRATING)) == GRATING
    assert variant_label(ROTATION).startswith("surface.glsl DIFFUSE=1 ENVIRONMENT_MAP=1")


@pytest.mark.gl
@pytest.mark.parametrize("key", [ROTATION, GRATING], ids=["rotation", "grating"])
def test_the_active_text_is_what_the_driver_compiles(renderer, key):
    """The kept lines alone compile, to a program with the same uniforms: a branch kept
    that the driver skips, or skipped that it keeps, would fail one or the other."""
    ctx = renderer.ctx
    program, defines = key
    full = renderer.programs.get(program, dict(defines))
    vertex, fragment = variant_text(key).split("// fragment")
    kept = ctx.program(vertex_shader=vertex.replace("// vertex\n", ""),
                       fragment_shader=fragment.lstrip("\n"))
    try:
        assert sorted(kept) == sorted(full)
        assert compose(program, "FRAGMENT_SHADER", dict(defines))[0].count("\n") > len(
            fragment.splitlines()) * 2  # comments and skipped branches are most of it
    finally:
        kept.release()
