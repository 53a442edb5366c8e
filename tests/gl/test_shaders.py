"""Shader composition (includes, defines, #line) and the variant cache (opaline.gl.shaders)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from opaline.gl import shaders
from opaline.gl.shaders import ProgramCache, ShaderError, annotate_log, compose, expand
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.model.request import resolve

LINE = re.compile(r"^#line (\d+) (\d+)$")


def fake_sources(monkeypatch, sources: dict[str, str]) -> None:
    """Serve shader sources from a dict instead of glsl/ (read_source is cached, so patch it)."""

    def read(name: str) -> str:
        if name not in sources:
            raise ShaderError(f"shader source not found: {name}")
        return sources[name]

    monkeypatch.setattr(shaders, "read_source", read)


def check_line_directives(source: str, files: list[str], read) -> int:
    """Walk a composed source: each body line must be the line its #line names; count them."""
    lines = source.splitlines()
    start = next(i for i, line in enumerate(lines) if LINE.match(line))
    current = None
    checked = 0
    for line in lines[start:]:
        match = LINE.match(line)
        if match:
            current = [int(match.group(1)), int(match.group(2))]
            continue
        number, index = current
        original = read(files[index]).splitlines()
        assert original[number - 1] == line, f"{files[index]}:{number} is not {line!r}"
        current[0] += 1
        checked += 1
    return checked


# Composition


def test_version_first_then_defines():
    """A composed stage starts with #version; stage and feature defines follow before the body."""
    source, _ = compose("surface.glsl", "FRAGMENT_SHADER",
                        {"MDF_MULTIPEAK": True, "LIGHT_COUNT": 3, "DIFFUSE": False})
    lines = source.splitlines()
    assert lines[0].startswith("#version ")
    first_body = next(i for i, line in enumerate(lines) if LINE.match(line))
    header = lines[1:first_body]
    assert "#define FRAGMENT_SHADER" in header
    assert "#define MDF_MULTIPEAK" in header
    assert "#define LIGHT_COUNT 3" in header
    assert not any("DIFFUSE" in line for line in header)  # False means "not defined"
    assert sum(line.startswith("#version") for line in lines) == 1


def test_precise_phase_raises_glsl_version():
    """PRECISE_PHASE (fp64 phase) asks for GLSL 4.00; without it 3.30 core."""
    defines = {"MDF_MULTIPEAK": True}
    precise, _ = compose("mdf_plot.glsl", "FRAGMENT_SHADER", {**defines, "PRECISE_PHASE": True})
    plain, _ = compose("mdf_plot.glsl", "FRAGMENT_SHADER", defines)
    assert precise.splitlines()[0] == "#version 400 core"
    assert plain.splitlines()[0] == "#version 330 core"


@pytest.mark.parametrize("program",
                         ["surface.glsl", "mdf_plot.glsl", "brdf_probe.glsl", "resolve.glsl"])
def test_line_directives_map_every_line_back(program):
    """#line directives are present and each body line is the line of the file they name."""
    defines = {"MDF_MULTIPEAK": True} if program != "resolve.glsl" else {}
    if program == "surface.glsl":
        defines.update(LIGHT_COUNT=2, FRESNEL=True, DIFFUSE=True, NORMAL_MAP=True)
    source, files = compose(program, "FRAGMENT_SHADER", defines)
    assert files[0] == program
    assert len(files) > 1, "the program includes lib/ files"
    assert source.count("#line") >= len(files)
    assert check_line_directives(source, files, shaders.read_source) > 20


def test_line_directives_resume_after_an_include(monkeypatch):
    """After an include the including file resumes at the line following the #include."""
    sources = {
        "main.glsl": '//! defines: FOO\nfloat a;\n#include "lib/x.glsl"\nfloat b;\n',
        "lib/x.glsl": "float x1;\nfloat x2;\n",
    }
    fake_sources(monkeypatch, sources)
    source, files = compose("main.glsl", "VERTEX_SHADER", {"FOO": True})
    assert files == ["main.glsl", "lib/x.glsl"]
    body = source.splitlines()[3:]
    assert body == ["#line 1 0", "//! defines: FOO", "float a;",
                    "#line 1 1", "float x1;", "float x2;",
                    "#line 4 0", "float b;"]


def test_unknown_define_is_refused():
    """A define the program does not declare raises ShaderError naming it."""
    with pytest.raises(ShaderError, match="MDF_MULTIPEEK"):
        compose("surface.glsl", "FRAGMENT_SHADER", {"MDF_MULTIPEEK": True})


def test_unknown_define_is_refused_by_the_cache():
    """The variant cache refuses an unknown define before touching GL."""
    cache = ProgramCache(ctx=None)
    with pytest.raises(ShaderError, match="NORMAL_MAPS"):
        cache.get("surface.glsl", {"MDF_MULTIPEAK": True, "NORMAL_MAPS": True})
    assert len(cache) == 0


def test_include_cycle_detected(monkeypatch):
    """a → b → a is an include cycle: ShaderError naming the chain."""
    fake_sources(monkeypatch, {
        "a.glsl": '//! defines:\n#include "b.glsl"\n',
        "b.glsl": '#include "a.glsl"\n',
    })
    with pytest.raises(ShaderError, match="include cycle") as info:
        expand("a.glsl", [])
    assert "a.glsl -> b.glsl -> a.glsl" in str(info.value)


def test_self_include_detected(monkeypatch):
    """A file including itself is a cycle too."""
    fake_sources(monkeypatch, {"a.glsl": '//! defines:\n#include "a.glsl"\n'})
    with pytest.raises(ShaderError, match="include cycle"):
        compose("a.glsl", "FRAGMENT_SHADER", {})


def test_diamond_include_is_not_a_cycle(monkeypatch):
    """Including one file from two branches is fine; its source number is shared."""
    fake_sources(monkeypatch, {
        "a.glsl": '//! defines:\n#include "b.glsl"\n#include "c.glsl"\n',
        "b.glsl": '#include "d.glsl"\n',
        "c.glsl": '#include "d.glsl"\n',
        "d.glsl": "float d;\n",
    })
    source, files = compose("a.glsl", "FRAGMENT_SHADER", {})
    assert files == ["a.glsl", "b.glsl", "d.glsl", "c.glsl"]
    assert source.count("float d;") == 2


def test_missing_include_names_the_file(monkeypatch):
    """An #include of a file that does not exist raises ShaderError naming it."""
    fake_sources(monkeypatch, {"a.glsl": '//! defines:\n#include "lib/nowhere.glsl"\n'})
    with pytest.raises(ShaderError, match="lib/nowhere.glsl"):
        compose("a.glsl", "FRAGMENT_SHADER", {})


def test_cycle_detected_in_real_files(glsl_copy):
    """An include cycle written into .glsl files on disk is detected too."""
    (glsl_copy / "lib" / "loop_a.glsl").write_text('#include "lib/loop_b.glsl"\n')
    (glsl_copy / "lib" / "loop_b.glsl").write_text('#include "lib/loop_a.glsl"\n')
    (glsl_copy / "loop.glsl").write_text('//! defines:\n#include "lib/loop_a.glsl"\n')
    with pytest.raises(ShaderError, match="include cycle"):
        compose("loop.glsl", "FRAGMENT_SHADER", {})


def test_annotate_log_names_files():
    """Mesa 'N:L(C)' and NVIDIA 'N(L)' source numbers become file:line."""
    files = ["surface.glsl", "lib/reflectance.glsl"]
    text = annotate_log("0:50(1): error: x\n1:12(7): error: y\n1(9) : error z", files)
    assert "surface.glsl:50" in text
    assert "lib/reflectance.glsl:12" in text
    assert "lib/reflectance.glsl:9" in text


# Digest


def test_sources_digest_matches_an_identical_copy(glsl_copy):
    """The digest depends on the sources only, not on where they live."""
    real = Path(shaders.__file__).resolve().parent.parent / "glsl"
    assert glsl_copy != real
    copy_digest = shaders.sources_digest()
    shaders.sources_digest.cache_clear()
    assert shaders.sources_digest() == copy_digest


def test_sources_digest_changes_when_a_source_changes(glsl_copy):
    """Editing, adding or renaming a .glsl file changes the digest; reverting restores it."""
    before = shaders.sources_digest()
    target = glsl_copy / "lib" / "common.glsl"
    original = target.read_text()
    digests = {before}

    target.write_text(original + "// a comment\n")
    shaders.sources_digest.cache_clear()
    digests.add(shaders.sources_digest())

    target.write_text(original)
    (glsl_copy / "lib" / "extra.glsl").write_text("float extra;\n")
    shaders.sources_digest.cache_clear()
    digests.add(shaders.sources_digest())

    (glsl_copy / "lib" / "extra.glsl").rename(glsl_copy / "lib" / "other.glsl")
    shaders.sources_digest.cache_clear()
    digests.add(shaders.sources_digest())

    (glsl_copy / "lib" / "other.glsl").unlink()
    shaders.sources_digest.cache_clear()
    assert shaders.sources_digest() == before
    assert len(digests) == 4


# Variant cache (needs GL)


def surface_program(renderer, preset_name: str, **fields):
    preset = get_preset(preset_name)
    job = resolve(RenderRequest(preset=preset_name, **fields), preset)
    defines = renderer.surface_defines(job, preset)
    return defines, renderer.programs.get("surface.glsl", defines)


@pytest.mark.gl
def test_each_variant_compiles_once(renderer, monkeypatch):
    """get() compiles a (program, defines) pair once; False defines do not make a new variant."""
    cache = ProgramCache(renderer.ctx)
    compiled = []
    real = cache._compile

    def counting(program, defines):
        compiled.append((program, dict(defines)))
        return real(program, defines)

    monkeypatch.setattr(cache, "_compile", counting)
    try:
        a = cache.get("resolve.glsl", {"TONEMAP_ACES": True})
        b = cache.get("resolve.glsl", {"TONEMAP_ACES": True, "TRANSPARENT": False})
        c = cache.get("resolve.glsl", {"TONEMAP_ACES": 1})
        assert a is b is c
        assert len(compiled) == 1 and len(cache) == 1
        d = cache.get("resolve.glsl", {"TONEMAP_REINHARD": True})
        e = cache.get("resolve.glsl")
        assert d is not a and e is not a and e is not d
        assert len(compiled) == 3 and len(cache) == 3
        cache.get("resolve.glsl", {})
        assert len(compiled) == 3
    finally:
        cache.release()
    assert len(cache) == 0


@pytest.mark.gl
def test_surface_defines_follow_the_scene(renderer):
    """Defines reflect the preset: MDF, normal map, tangent field and light count."""
    cd, _ = surface_program(renderer, "cd-rom")
    assert cd["MDF_MULTIPEAK"] and not cd["MDF_ASHIKHMIN"]
    assert not cd["NORMAL_MAP"] and cd["TANGENT_CONCENTRIC"]
    assert cd["LIGHT_COUNT"] == len(get_preset("cd-rom").lights)
    nacre, _ = surface_program(renderer, "nacre")
    assert nacre["NORMAL_MAP"] and not nacre["TANGENT_CONCENTRIC"]
    assert nacre["LIGHT_COUNT"] == len(get_preset("nacre").lights)
    ash, _ = surface_program(renderer, "cd-rom-ashikhmin")
    assert ash["MDF_ASHIKHMIN"] and not ash["MDF_MULTIPEAK"]


@pytest.mark.gl
def test_cd_rom_compiles_only_what_it_needs(renderer):
    """cd-rom's surface variant has no normal map, no A-S exponents and (f0 = 1) no Fresnel."""
    _, program = surface_program(renderer, "cd-rom")
    assert program.get("u_normal_map", None) is None
    assert program.get("u_ex", None) is None and program.get("u_ey", None) is None
    assert program.get("u_f0", None) is None
    assert program.get("u_mu_f", None) is not None


@pytest.mark.gl
def test_nacre_has_a_normal_map(renderer):
    """nacre's surface variant samples a normal map."""
    _, program = surface_program(renderer, "nacre")
    assert program.get("u_normal_map", None) is not None


@pytest.mark.gl
def test_ashikhmin_variant_has_exponents_not_frequency(renderer):
    """The A-S variant reads ex, ey and none of the multi-peak parameters."""
    _, program = surface_program(renderer, "cd-rom-ashikhmin")
    assert program.get("u_ex", None) is not None
    assert program.get("u_mu_f", None) is None and program.get("u_alpha", None) is None


@pytest.mark.gl
def test_fresnel_and_diffuse_only_when_used(renderer):
    """f0 < 1 adds u_f0; kd = 0 removes u_kd (and kd > 0 keeps it)."""
    _, fresnel = surface_program(renderer, "cd-rom", f0=0.5)
    assert fresnel.get("u_f0", None) is not None
    defines, no_diffuse = surface_program(renderer, "cd-rom", kd=0.0)
    assert not defines["DIFFUSE"]
    assert no_diffuse.get("u_kd", None) is None
    _, diffuse = surface_program(renderer, "cd-rom", kd=0.3)
    assert diffuse.get("u_kd", None) is not None


@pytest.mark.gl
def test_compile_failure_names_the_file_and_line(renderer):
    """LIGHT_COUNT=0 fails to compile; the ShaderError points at surface.glsl's light arrays."""
    with pytest.raises(ShaderError) as info:
        renderer.programs.get("surface.glsl", {"MDF_MULTIPEAK": True, "LIGHT_COUNT": 0})
    message = str(info.value)
    assert re.search(r"\bsurface\.glsl:\d+", message)
    source = shaders.read_source("surface.glsl").splitlines()
    line = next(i for i, text in enumerate(source, 1) if "u_light_position[LIGHT_COUNT]" in text)
    assert f"surface.glsl:{line}" in message


@pytest.mark.gl
def test_compile_failure_in_an_include_names_the_included_file(renderer, glsl_copy):
    """An error inside an included lib file is reported as that file and its line."""
    (glsl_copy / "lib" / "broken.glsl").write_text("// fine\n// fine\nfloat oops = ;\n")
    (glsl_copy / "broken_prog.glsl").write_text(
        '//! defines:\n#include "fullscreen.glsl"\n#ifdef FRAGMENT_SHADER\n'
        '#include "lib/broken.glsl"\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n#endif\n'
    )
    cache = ProgramCache(renderer.ctx)
    try:
        with pytest.raises(ShaderError) as info:
            cache.get("broken_prog.glsl")
    finally:
        cache.release()
    assert "lib/broken.glsl:3" in str(info.value)
