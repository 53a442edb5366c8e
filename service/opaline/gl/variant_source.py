"""The source a program variant compiles: its composed text with the inactive
conditional branches, comments, blank lines and ``#line`` markers taken out.

A hash of every ``.glsl`` file (``sources_digest``) changes with any edit, a comment
included, and so marks every measurement stale. What a variant's image depends on is
only this text; ``variant_digest`` hashes it, so the accuracy table can say, preset by
preset, whether the programs it was measured with are still the ones that compile
(bench/accuracy.py, tests/model/test_auto.py).

Only the preprocessor's conditionals are evaluated, over the subset the project's
shaders use: ``#ifdef``, ``#ifndef``, ``#if``/``#elif`` with ``defined``, integer
macros, one comparison between ``&&``/``||``, ``!`` before ``defined``, non-negative
arithmetic, ``#else``, ``#endif``, ``#define``, ``#undef``; an extension the source
enables counts as defined, as the driver that has it defines its macro (the table is
measured on one that has them). Anything else is an error, not a guess. Macros are not
expanded in code, so an active ``#define`` stays in the text (changing its value changes
the digest). pcpp, a full C preprocessor in Python, took 0.4-1.8 s a stage and rewrote
code lines; this takes milliseconds; over the 377 variants of the table and 203 random
define sets it keeps the lines gcc's ``cpp -P -undef`` keeps.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterable

from opaline.gl.shaders import ProgramKey, ShaderError, compose

DIRECTIVE = re.compile(r"^\s*#\s*(\w+)\s*(.*?)\s*$")
DEFINED = re.compile(r"\bdefined\s*(?:\(\s*(\w+)\s*\)|(\w+))")
MACRO_CALL = re.compile(r"\b[A-Za-z_]\w*\s*\(")  # function-like macros are not in it
# Where the C and the translated Python readings differ: `!` on anything but defined
# (Python's `not` binds looser than ==), a single & or |, and / or % with a negative.
UNSAFE = re.compile(r"!(?!=)(?!\s*defined\b)|(?<![&|])[&|](?![&|])")
COMPARISON = re.compile(r"==|!=|<=|>=|<|>")
IDENTIFIER = re.compile(r"\b[A-Za-z_]\w*\b")
EXPRESSION = re.compile(r"^[\d\s()+\-*/%<>=!&|]*$")  # what is left once names are numbers
CONDITIONALS = {"if", "ifdef", "ifndef", "elif", "else", "endif"}


def evaluate(expression: str, macros: dict[str, int | None]) -> bool:
    """A ``#if``'s condition: ``defined`` first, then each name as its value (0 when it is
    not defined, as C has it)."""
    outside = ShaderError(f"#if {expression!r}: outside the subset variant_source evaluates")
    if UNSAFE.search(expression) or any(
            len(COMPARISON.findall(part)) > 1 for part in re.split(r"&&|\|\||[()]", expression)):
        raise outside  # chained comparisons too: C compares the first's 0 or 1
    text = DEFINED.sub(lambda m: "1" if (m.group(1) or m.group(2)) in macros else "0",
                       expression)
    if MACRO_CALL.search(text):
        raise outside
    names = IDENTIFIER.findall(text)
    if any(name in macros and macros[name] is None for name in names):
        raise outside  # a macro whose body is not an integer
    text = IDENTIFIER.sub(lambda m: str(macros.get(m.group(0), 0)), text)
    if not EXPRESSION.match(text) or ("-" in text and ("/" in text or "%" in text)):
        raise outside
    python = (text.replace("&&", " and ").replace("||", " or ").replace("/", "//")
              .replace("!=", "\0").replace("!", " not ").replace("\0", "!="))
    try:
        return bool(eval(python, {"__builtins__": {}}))  # noqa: S307 (digits and operators)
    except (SyntaxError, ArithmeticError) as exc:
        raise outside from exc


def _macro_value(rest: str) -> tuple[str, int | None]:
    """A ``#define``'s name and integer value: 1 for an empty body (only ``defined`` reads
    it), None for any other (an ``#if`` that reads it is an error)."""
    head = re.match(r"(\w+)(\()?\s*(.*)", rest)
    if head is None:
        raise ShaderError(f"#define {rest!r}: no name")
    name, call, value = head.groups()
    if call or not value:
        return name, None if call else 1
    return name, int(value) if re.fullmatch(r"-?\d+", value) else None


def active_lines(source: str) -> list[str]:
    """The lines a preprocessor would keep, comments stripped, blank lines dropped."""
    macros: dict[str, int | None] = {}
    # Per open conditional: (this branch is on, some branch has been on, the enclosing is on)
    stack: list[tuple[bool, bool, bool]] = []
    on = True
    out = []
    for raw in source.splitlines():
        line = raw.split("//", 1)[0].rstrip()
        if "/*" in line:
            raise ShaderError(f"{line.strip()!r}: block comments are outside the subset")
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
            elif kind == "undef":
                macros.pop(rest.split()[0], None)
            elif kind == "extension":
                macros[rest.split()[0]] = 1
            elif kind == "error":
                raise ShaderError(f"#error {rest}")
            out.append(line.strip())
    if stack:
        raise ShaderError("unterminated #if")
    return out


def _branch(kind: str, rest: str, stack: list[tuple[bool, bool, bool]],
            macros: dict[str, int | None], on: bool) -> bool:
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
