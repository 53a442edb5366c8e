"""Where each entry of a manifest starts, so that a bad entry's error names its line.

The parsers (tomllib, json) give values, not positions; a manifest's entries are found
again in its text: in TOML each ``[[material]]`` header, or the elements of an inline
``material = [...]``; in JSON the elements of the top-level ``"material"`` array. The
scanner knows strings, comments and nesting, nothing more: the text has already parsed.
Where what it finds does not match the parsed entries one for one, no line is given.
"""

from __future__ import annotations

import re

TOML_ENTRY = re.compile(r"""^[ \t]*\[\[[ \t]*(?:material|"material"|'material')[ \t]*\]\]""",
                        re.MULTILINE)
TOML_ARRAY = re.compile(r"""^[ \t]*(?:material|"material"|'material')[ \t]*=[ \t]*\[""",
                        re.MULTILINE)
OPENING = "[{"
CLOSING = "]}"


def entry_lines(text: str, is_json: bool) -> list[int]:
    """The 1-based line of each entry, in order."""
    if is_json:
        starts = _json_entries(text)
    else:
        starts = [m.start() for m in TOML_ENTRY.finditer(text)]
        array = TOML_ARRAY.search(text)
        if not starts and array is not None:
            starts = _elements(text, array.end() - 1, toml=True)
    return [text.count("\n", 0, start) + 1 for start in starts]


def _json_entries(text: str) -> list[int]:
    """Offsets of the elements of the top-level ``"material"`` array."""
    depth, i, key = 0, 0, None
    while i < len(text):
        c = text[i]
        if c == '"':
            end = _string_end(text, i, toml=False)
            if depth == 1:
                key = text[i + 1:end - 1]
            i = end
            continue
        if c == "[" and depth == 1 and key == "material":
            return _elements(text, i, toml=False)
        depth += (c in OPENING) - (c in CLOSING)
        i += 1
    return []


def _elements(text: str, opening: int, toml: bool) -> list[int]:
    """Offsets of the elements of the array whose ``[`` is at ``opening``."""
    found: list[int] = []
    depth, i, expecting = 0, opening + 1, True
    while i < len(text):
        c = text[i]
        if c.isspace() or (toml and c == "#"):
            i = text.find("\n", i) if c == "#" else i + 1
            if i < 0:
                break
            continue
        if depth == 0 and c == "]":
            return found
        if expecting and depth == 0:
            found.append(i)
            expecting = False
        if c == '"' or (toml and c == "'"):
            i = _string_end(text, i, toml)
            continue
        if depth == 0 and c == ",":
            expecting = True
        depth += (c in OPENING) - (c in CLOSING)
        i += 1
    return found


def _string_end(text: str, start: int, toml: bool) -> int:
    """The offset just past the string opening at ``start`` (TOML's literal and multi-line
    forms too)."""
    quote = text[start]
    if toml and text.startswith(quote * 3, start):
        end = text.find(quote * 3, start + 3)
        while end >= 0 and quote == '"' and _escaped(text, end):
            end = text.find(quote * 3, end + 1)
        return len(text) if end < 0 else end + 3
    i = start + 1
    while i < len(text) and text[i] != quote:
        i += 2 if text[i] == "\\" and quote == '"' else 1
    return i + 1


def _escaped(text: str, at: int) -> bool:
    """Whether the character at ``at`` follows an odd run of backslashes."""
    run = len(text[:at]) - len(text[:at].rstrip("\\"))
    return run % 2 == 1
