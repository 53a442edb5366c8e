"""Where each entry of a manifest starts, so that a bad entry's error names its line.

The parsers (tomllib, json) give values, not positions; a manifest's entries are found
again in its text: in TOML each ``[[material]]`` header, in JSON each object directly
inside the top-level ``"material"`` array (a small scanner that knows strings and
nesting, nothing more: the text has already parsed).
"""

from __future__ import annotations

import re

TOML_ENTRY = re.compile(r"""^[ \t]*\[\[[ \t]*(?:material|"material"|'material')[ \t]*\]\]""",
                        re.MULTILINE)


def entry_lines(text: str, is_json: bool) -> list[int]:
    """The 1-based line of each entry, in order; fewer (or none) where the entries are
    written in a form not scanned for (TOML's inline array of tables)."""
    starts = _json_entries(text) if is_json else [m.start() for m in TOML_ENTRY.finditer(text)]
    return [text.count("\n", 0, start) + 1 for start in starts]


def _json_entries(text: str) -> list[int]:
    """Offsets of the objects in the top-level ``"material"`` array."""
    depth, i, key, found = 0, 0, None, []
    array_depth = None  # the depth inside the material array, once entered
    while i < len(text):
        c = text[i]
        if c == '"':
            end = _string_end(text, i)
            if depth == 1 and array_depth is None:
                key = text[i + 1:end]
            i = end + 1
            continue
        if c in "{[":
            if c == "[" and depth == 1 and key == "material" and array_depth is None:
                array_depth = depth + 1
            elif c == "{" and array_depth is not None and depth == array_depth:
                found.append(i)
            depth += 1
        elif c in "}]":
            depth -= 1
            if array_depth is not None and depth < array_depth:
                return found
        i += 1
    return found


def _string_end(text: str, start: int) -> int:
    """The offset of the quote that closes the string opening at ``start``."""
    i = start + 1
    while i < len(text) and text[i] != '"':
        i += 2 if text[i] == "\\" else 1
    return i
