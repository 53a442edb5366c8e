"""The source a program variant compiles: its composed text with the inactive
conditional branches, comments, blank lines and ``#line`` markers taken out.

A hash of every ``.glsl`` file (``sources_digest``) changes with any edit, a comment
included, and so marks every measurement stale. What a variant's image depends on is
only this text; ``variant_digest`` hashes it, so the accuracy table can say, preset by
preset, whether the programs it was measured with are still the ones that compile
(bench/accuracy.py, tests/model/test_auto.py).

Only the preprocessor's conditionals are evaluated, over the subset the project's
shaders use: ``#ifdef``, ``#ifndef``, ``#if``/``#elif`` with ``defined``, integer
macros, comparisons, arithmetic and ``&&``/``||``/``!``, ``#else``, ``#endif``,
``#define``. Macros are not expanded in code, so an active ``#define`` stays in the text
(changing its value changes the digest). pcpp, a full C preprocessor in Python, took
0.4-1.8 s a stage and rewrote code lines; this takes milliseconds.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterable

from opaline.gl.shaders import ProgramKey, ShaderError, compose

DIRECTIVE = re.compile(r"^\s*#\s*(\w+)\s*(.*?)\s*$")
DEFINED = re.compile(r"\bdefined\s*(?:\(\s*(\w+)\s*\)|(\w+))")
MACRO_CALL = re.compile(r"\b[A-Za-z_]\w*\s*\(")  # function-like macros are not in it
IDENTIFIER = re.compile(r"\b[A-Za-z_]\w*\b")
EXPRESSION = re.compile(r"^[\d\s()+\-*/%<>=!&|]*$")  # what is left once names are numbers
CONDITIONALS = {"if", "ifdef", "ifndef", "elif", "else", "endif"}


def evaluate(expression: str, macros: dict[str, int]) -> bool:
    """A ``#if``'s condition: ``defined`` first, then each name as its value (0 when it is
    not defined, as C has it)."""
    text = DEFINED.sub(lambda m: "1" if (m.group(1) or m.group(2)) in macros else "0",
                       expression)
    outside = ShaderError(f"#if {expression!r}: outside the subset variant_source evaluates")
    if MACRO_CALL.search(text):
        raise outside
    text = IDENTIFIER.sub(lambda m: str(macros.get(m.group(0), 0)), text)
    if not EXPRESSION.match(text):
        raise outside
    python = (text.replace("&&", " and ").replace("||", " or ").replace("/", "//")
              .replace("!=", "\0").replace("!", " not ").replace("\0", "!="))
    try:
        return bool(eval(python, {"__builtins__": {}}))  # noqa: S307 (digits and operators)
    except (SyntaxError, ArithmeticError) as exc:
        raise outside from exc


def _macro_value(rest: str) -> tuple[str, int]:
    name, _, value = rest.partition(" ")
    value = value.strip()
    return name, int(value) if re.fullmatch(r"-?\d+", value) else 1


def active_lines(source: str) -> list[str]:
    """The lines a preprocessor would keep, comments stripped, blank lines dropped."""
    macros: dict[str, int] = {}
    # Per open conditional: (this branch is on, some branch has been on, the enclosing is on)
    stack: list[tuple[bool, bool, bool]] = []
    on = True
    out = []
    for raw in source.splitlines():
        line = raw.split("//", 1)[0].rstrip()
        match = DIRECTIVE.match(line)
        kind, rest = (match.group(1), match.group(2)) if match else ("", "")
        if kind in CONDITIONALS:
            on = _branch(kind, rest, stack, macros, on)
        elif not on or not line.strip() or kind == "line":
            continue
        else:
            if kind == "define":
                name, value = _macro_value(rest)
                macros[name] = value
            elif kind == "error":
                raise ShaderError(f"#error {rest}")
            out.append(line.strip())
    if stack:
        raise ShaderError("unterminated #if")
    return out


def _branch(kind: str, rest: str, stack: list[tuple[bool, bool, bool]],
            macros: dict[str, int], on: bool) -> bool:
    """The state after one conditional directive; ``stack`` changes in place."""
    if kind in ("if", "ifdef", "ifndef"):
        if not on:
            stack.append((False, True, False))  # nothing inside an off branch is on
            return False
        taken = (evaluate(rest, macros) if kind == "if"
                 else (rest.split()[0] in macros) == (kind == "ifdef"))
        stack.append((taken, taken, True))
        return taken
    if not stack:
        raise ShaderError(f"#{kind} without #if")
    _, done, outer = stack.pop()
    if kind == "endif":
        return stack[-1][0] if stack else True
    taken = outer and not done and (kind == "else" or evaluate(rest, macros))
    stack.append((taken, done or taken, outer))
    return taken


def variant_text(key: ProgramKey) -> str:
    """Both stages of one variant as they compile."""
    program, defines = key
    stages = [active_lines(compose(program, stage, dict(defines))[0])
              for stage in ("VERTEX_SHADER", "FRAGMENT_SHADER")]
    return "\n".join(["// vertex", *stages[0], "// fragment", *stages[1]])


def variant_label(key: ProgramKey) -> str:
    """A variant as the accuracy table lists it: ``surface.glsl ENV_SAMPLES=6 MDF_ASHIKHMIN=1``."""
    program, defines = key
    return " ".join([program, *(f"{name}={value}" for name, value in defines)])


def variant_key(label: str) -> ProgramKey:
    """The variant a ``variant_label`` names."""
    program, *defines = label.split()
    pairs = (define.partition("=") for define in defines)
    return program, tuple((name, int(value)) for name, _, value in pairs)


def variant_digest(keys: Iterable[ProgramKey]) -> str:
    """One hash of the compiled text of every variant in ``keys`` (order and repeats aside)."""
    digest = hashlib.sha256()
    for key in sorted(set(keys)):
        digest.update(repr(key).encode())
        digest.update(variant_text(key).encode())
    return digest.hexdigest()[:16]
