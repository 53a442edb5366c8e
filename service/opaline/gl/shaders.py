"""Shader programs from ``glsl/``: includes, feature defines, a variant cache.

Each program is one ``.glsl`` file holding every stage behind
``#ifdef VERTEX_SHADER`` / ``FRAGMENT_SHADER`` (as moderngl-window does). Its
first line declares the feature defines it understands; asking for any other
is an error, so a typo cannot silently compile the wrong variant. ``#include``
is resolved recursively with a cycle guard, and ``#line`` directives map the
driver's error lines back to files.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable, Mapping
from functools import cache

import moderngl

from opaline.lru import BudgetLRU
from opaline.resources import glsl_root, sources_digest  # noqa: F401 (re-exported)

log = logging.getLogger(__name__)

INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
DECLARED = re.compile(r"^//!\s*defines:(.*)$")
BRANCH = re.compile(r"^\s*#\s*(?:else|elif|endif)\b")

Defines = Mapping[str, int | bool]
# Features that ask for an optional GL extension: enabled where the driver has it (a
# warning where not), and the GLSL tests its macro and falls back.
EXTENSIONS = {"ENV_QUAD_MEAN": "GL_ARB_derivative_control",
              "COAT_QUAD_MEAN": "GL_ARB_derivative_control"}
# A compiled variant: its program file and its defines that are on, sorted (name, value).
ProgramKey = tuple[str, tuple[tuple[str, int], ...]]


class ShaderError(RuntimeError):
    """A shader failed to compose or compile; the log names files and lines."""


@cache
def read_source(name: str) -> str:
    path = glsl_root() / name
    if not path.is_file():
        raise ShaderError(f"shader source not found: {name}")
    return path.read_text()


def declared_defines(program: str) -> frozenset[str]:
    first = read_source(program).splitlines()[0]
    match = DECLARED.match(first)
    return frozenset(match.group(1).split()) if match else frozenset()


def expand(name: str, files: list[str], stack: tuple[str, ...] = ()) -> list[str]:
    """Lines of ``name`` with includes inlined; ``files`` collects source numbers."""
    if name in stack:
        raise ShaderError("include cycle: " + " -> ".join((*stack, name)))
    if name not in files:
        files.append(name)
    index = files.index(name)
    out = [f"#line 1 {index}"]
    for number, line in enumerate(read_source(name).splitlines(), start=1):
        match = INCLUDE.match(line)
        if match:
            out.extend(expand(match.group(1), files, (*stack, name)))
            out.append(f"#line {number + 1} {index}")
        else:
            out.append(line)
            if BRANCH.match(line):
                # The #line after an include in a skipped branch is skipped with it:
                # each branch's end puts the numbering back.
                out.append(f"#line {number + 1} {index}")
    return out


def compose(program: str, stage: str, defines: Defines) -> tuple[str, list[str]]:
    """Full source for one stage of a program variant, and its file table."""
    unknown = set(defines) - declared_defines(program)
    if unknown:
        raise ShaderError(f"{program} has no feature(s) {sorted(unknown)}")
    precise = bool(defines.get("PRECISE_PHASE"))
    header = ["#version 400 core" if precise else "#version 330 core"]
    header += [f"#extension {name} : enable"
               for name in sorted({EXTENSIONS[key] for key in EXTENSIONS if defines.get(key)})]
    header.append(f"#define {stage}")
    for key in sorted(defines):
        value = defines[key]
        if value is False:
            continue
        header.append(f"#define {key}" if value is True else f"#define {key} {int(value)}")
    files: list[str] = []
    body = expand(program, files)
    return "\n".join(header + body) + "\n", files


# Driver logs locate errors as "SOURCE:LINE(COL)" (Mesa) or "SOURCE(LINE)" (NVIDIA).
LOG_LOCATION = re.compile(r"\b(\d+)(?::(\d+)\(\d+\)|\((\d+)\))")


def annotate_log(message: str, files: list[str]) -> str:
    """Replace the driver's source numbers by the file names of the ``#line`` table."""

    def located(match: re.Match[str]) -> str:
        index = int(match.group(1))
        label = files[index] if index < len(files) else f"source {index}"
        return f"{label}:{match.group(2) or match.group(3)}"

    return LOG_LOCATION.sub(located, message)


# A linked surface variant holds about 1.7 MB in llvmpipe (its JIT code and state),
# measured as the RSS growth over 252 distinct variants; the budget counts that.
PROGRAM_BYTES = 2 * 1024 * 1024


class ProgramCache:
    """Compiled program variants for one context, keyed by program and defines, kept
    under a count budget (LRU). ``on_release`` hears of each program before it is freed,
    so that vertex arrays made for it can go too (GL reuses the freed names)."""

    def __init__(self, ctx: moderngl.Context, max_programs: int = 64,
                 on_release: Callable[[moderngl.Program], None] | None = None) -> None:
        self.ctx = ctx
        self.on_release = on_release
        self._programs: BudgetLRU[ProgramKey, moderngl.Program] = BudgetLRU(
            max_programs, max_programs * PROGRAM_BYTES, release=self._release)
        # When set, every variant asked for is added to it: the accuracy benchmark stamps
        # its measurements with them (gl/variant_source.py).
        self.record: set[ProgramKey] | None = None

    def __len__(self) -> int:
        return len(self._programs)

    @property
    def evictions(self) -> int:
        return self._programs.evictions

    def get(self, program: str, defines: Defines | None = None) -> moderngl.Program:
        defines = {k: v for k, v in (defines or {}).items() if v is not False}
        key = (program, tuple(sorted((k, int(v)) for k, v in defines.items())))
        if self.record is not None:
            self.record.add(key)
        found = self._programs.get(key)
        if found is None:
            found = self._compile(program, defines)
            self._programs.put(key, found, PROGRAM_BYTES)
        return found

    def _compile(self, program: str, defines: Defines) -> moderngl.Program:
        vertex, files = compose(program, "VERTEX_SHADER", defines)
        fragment, _ = compose(program, "FRAGMENT_SHADER", defines)
        try:
            return self.ctx.program(vertex_shader=vertex, fragment_shader=fragment)
        except Exception as exc:  # moderngl raises a bare Error with the driver log
            detail = annotate_log(str(exc), files)
            log.error("shader %s %s failed to compile:\n%s", program, dict(defines), detail)
            raise ShaderError(f"{program} {dict(defines)} failed to compile: {detail}") from exc

    def _release(self, program: moderngl.Program) -> None:
        if self.on_release is not None:
            self.on_release(program)
        program.release()

    def release(self) -> None:
        self._programs.clear()
