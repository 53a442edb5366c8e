"""One material file on disk: read it, validate it, and say where in it a problem is.

Errors name the file and, where it is known, the line, compiler-style
(``disc.toml:3: mu_f=5000 is out of range ...``), so editors and CI annotations
can jump there: syntax errors carry the parser's line, a validation error the
line where its key is written.
"""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from opaline.model.params import RenderRequest, describe_errors
from opaline.model.strict_json import DuplicateKey, refuse_duplicate_keys, validate_strictly
from opaline.scene.environments import SUFFIXES as ENVIRONMENT_SUFFIXES
from opaline.scene.environments import expand_user

SUFFIXES = (".toml", ".json")
SCHEMA_KEY = "$schema"  # allowed in files so editors can find the schema; ignored
TOML_LINE = re.compile(r"\(at line (\d+),")


class MaterialError(ValueError):
    """A material file or manifest is unreadable or invalid; the message names the file.

    ``path`` and ``line`` (1-based, or None) say where, for CI annotations."""

    def __init__(self, message: str, path: Path | str | None = None,
                 line: int | None = None) -> None:
        super().__init__(message)
        self.path = None if path is None else str(path)
        self.line = line


def at(path: Path | str, line: int | None) -> str:
    """``path`` or ``path:line``: how every message starts."""
    return f"{path}:{line}" if line else str(path)


def read_text_table(path: Path) -> tuple[dict[str, Any], str]:
    """The top-level table of a TOML or JSON file, and the file's text."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise MaterialError(f"{path}: cannot read: {reason}", path) from None
    is_json = path.suffix.lower() == ".json"
    try:
        data = json.loads(text) if is_json else tomllib.loads(text)
        if is_json:  # TOML refuses a key given twice itself
            refuse_duplicate_keys(text, "the file")
    except DuplicateKey as exc:
        raise MaterialError(f"{path}: {exc}", path) from None
    except json.JSONDecodeError as exc:
        raise MaterialError(f"{at(path, exc.lineno)}: invalid JSON: {exc}", path,
                            exc.lineno) from None
    except tomllib.TOMLDecodeError as exc:
        found = TOML_LINE.search(str(exc))  # tomllib keeps the line only in its message
        line = int(found.group(1)) if found else None
        raise MaterialError(f"{at(path, line)}: invalid TOML: {exc}", path, line) from None
    if not isinstance(data, dict):
        raise MaterialError(f"{path}: expected a table of fields, got {type(data).__name__}",
                            path)
    data.pop(SCHEMA_KEY, None)
    return data, text


def read_table(path: Path) -> dict[str, Any]:
    """The top-level table of a TOML or JSON file."""
    return read_text_table(path)[0]


def key_line(text: str, key: str, is_json: bool) -> int | None:
    """The line where top-level ``key`` is written: a plain scan, enough for flat files."""
    name = re.escape(key)
    pattern = rf'"{name}"\s*:' if is_json else rf'^[ \t]*(?:{name}|"{name}"|\'{name}\')[ \t]*='
    found = re.search(pattern, text, re.MULTILINE)
    return text.count("\n", 0, found.start()) + 1 if found else None


def locate(path: Path | str, key: str) -> int | None:
    """``key_line`` of a file on disk (None if it cannot be read)."""
    path = Path(path)
    try:
        return key_line(path.read_text(encoding="utf-8"), key, path.suffix.lower() == ".json")
    except (OSError, UnicodeDecodeError):
        return None


def validate(fields: dict[str, Any], lax: Iterable[str] = ()) -> RenderRequest:
    """Fields as a request: a file's strictly, as the API reads a JSON body ({"mu_f": "6"} is
    refused), the ``lax`` ones (the command line's --set strings) as pydantic parses them."""
    lax = set(lax)
    validate_strictly({k: v for k, v in fields.items() if k not in lax}, RenderRequest)
    return RenderRequest.model_validate(fields)


def parse_request(fields: dict[str, Any], where: str, lax: Iterable[str] = ()) -> RenderRequest:
    """Validate fields with the request model; errors name ``where``, the field and the range."""
    try:
        return validate(fields, lax)
    except ValidationError as exc:
        raise MaterialError(f"{where}: " + "; ".join(describe_errors(exc))) from None


def load_material(path: Path | str, overrides: dict[str, Any] | None = None) -> RenderRequest:
    """Parse one material file; ``overrides`` win over the file's fields.

    An empty file is an error: rendering the default sphere for it would hide the mistake."""
    path = Path(path)
    fields, text = read_text_table(path)
    if not fields:
        raise MaterialError(f"{path}: empty material file: expected fields such as "
                            'preset = "cd-rom" (see `opaline schema`)', path)
    own = set(fields) - set(overrides or {})
    fields = files_beside(path, fields)
    fields.update(overrides or {})
    try:
        return validate(fields, set(fields) - own)
    except ValidationError as exc:
        line = _first_line(exc, text, own, path.suffix.lower() == ".json")
        raise MaterialError(f"{at(path, line)}: " + "; ".join(describe_errors(exc)), path,
                            line) from None


def files_beside(path: Path, fields: dict[str, Any]) -> dict[str, Any]:
    """``fields`` as written in the file at ``path``, its mesh and environment files found
    as an editor sees them: relative to that file, not to where the command runs."""
    found = dict(fields)
    if isinstance(found.get("mesh"), str):
        found["mesh"] = str(path.parent / expand_user(Path(found["mesh"])))
    if isinstance(found.get("environment"), str):
        found["environment"] = environment_beside(path, found["environment"])
    return found


def environment_beside(path: Path, environment: str) -> str:
    """An environment file written in a material file: a path is relative to the file, as
    a mesh is, and so is a bare file name that is there. Any other name is a built-in's or
    one of the environments folder's (scene.environments.check_name)."""
    if not environment.lower().endswith(ENVIRONMENT_SUFFIXES):
        return environment
    written = expand_user(Path(environment))
    beside = path.parent / written
    if written.name != environment or beside.is_file():
        return str(beside)
    return environment


def _first_line(exc: ValidationError, text: str, own: Iterable[str], is_json: bool) -> int | None:
    """The line of the first problem that is a key written in the file (not an override)."""
    for err in exc.errors():
        key = str(err["loc"][0]) if err["loc"] else ""
        if key in own:
            line = key_line(text, key, is_json)
            if line:
                return line
    return None
