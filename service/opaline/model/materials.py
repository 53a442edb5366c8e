"""Material files and manifests: render requests kept on disk (docs/materials.md).

A material file is one TOML or JSON table holding the fields of a render
request (``params.RenderRequest``): preset, material parameters, size,
format, quality. It parses into that same model, so a range is checked the
same way as over HTTP, and an error names the file, the field, the value and
the allowed range.

A manifest (``*.manifest.toml`` / ``*.manifest.json``) lists many materials:
``[[material]]`` entries, each inline (``name`` plus fields) or a ``path`` to
a material file (plus optional ``name`` and overrides), under an optional
``[defaults]`` table. Merge order: manifest defaults, the file, the entry.

Collecting never raises for a bad input: each problem becomes an ``Item``
with an ``error``, so a batch can render every other input.
"""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from opaline.model.params import RenderRequest, describe_errors

SUFFIXES = (".toml", ".json")
MANIFEST_SUFFIXES = (".manifest.toml", ".manifest.json")
SCHEMA_KEY = "$schema"  # allowed in files so editors can find the schema; ignored
# An output name: every segment starts with a letter or digit, so no "..", no hidden
# file and no absolute path can escape the output folder.
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*(/[A-Za-z0-9][A-Za-z0-9._-]*)*$")
MANIFEST_KEYS = {"defaults", "material"}
ENTRY_KEYS = {"name", "path"}


class MaterialError(ValueError):
    """A material file or manifest is unreadable or invalid; the message names the file."""


@dataclass
class Item:
    """One thing to render: a stable output name, where it came from, and the request or why not."""

    name: str
    source: str
    request: RenderRequest | None = None
    error: str | None = None


def is_manifest(path: Path) -> bool:
    return path.name.lower().endswith(MANIFEST_SUFFIXES)


def read_table(path: Path) -> dict[str, Any]:
    """The top-level table of a TOML or JSON file."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise MaterialError(f"{path}: cannot read: {exc.strerror or exc}") from None
    is_json = path.suffix.lower() == ".json"
    try:
        data = json.loads(text) if is_json else tomllib.loads(text)
    except (json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        raise MaterialError(f"{path}: invalid {'JSON' if is_json else 'TOML'}: {exc}") from None
    if not isinstance(data, dict):
        raise MaterialError(f"{path}: expected a table of fields, got {type(data).__name__}")
    data.pop(SCHEMA_KEY, None)
    return data


def parse_request(fields: dict[str, Any], where: str) -> RenderRequest:
    """Validate fields with the request model; errors name ``where``, the field and the range."""
    try:
        return RenderRequest.model_validate(fields)
    except ValidationError as exc:
        raise MaterialError(f"{where}: " + "; ".join(describe_errors(exc))) from None


def load_material(path: Path | str, overrides: dict[str, Any] | None = None) -> RenderRequest:
    """Parse one material file; ``overrides`` win over the file's fields."""
    path = Path(path)
    fields = read_table(path)
    fields.update(overrides or {})
    return parse_request(fields, str(path))


def material_items(path: Path, name: str, overrides: dict[str, Any]) -> list[Item]:
    try:
        return [Item(name, str(path), load_material(path, overrides))]
    except MaterialError as exc:
        return [Item(name, str(path), error=str(exc))]


def manifest_items(path: Path, prefix: str, overrides: dict[str, Any]) -> list[Item]:
    """Every entry of a manifest; entry names are prefixed with ``prefix``."""
    try:
        data = read_table(path)
        entries, defaults = _manifest_parts(path, data)
    except MaterialError as exc:
        return [Item(prefix + path.name.split(".")[0], str(path), error=str(exc))]
    return [_entry_item(path, index, entry, defaults, prefix, overrides)
            for index, entry in enumerate(entries)]


def _manifest_parts(path: Path, data: dict) -> tuple[list, dict]:
    unknown = sorted(set(data) - MANIFEST_KEYS)
    if unknown:
        raise MaterialError(f"{path}: unknown key(s) {', '.join(unknown)} "
                            "(known: defaults, material)")
    entries = data.get("material")
    if not isinstance(entries, list) or not entries:
        raise MaterialError(f"{path}: expected a non-empty list of [[material]] entries")
    defaults = data.get("defaults", {})
    if not isinstance(defaults, dict):
        raise MaterialError(f"{path}: [defaults] must be a table")
    return entries, defaults


def _entry_item(manifest: Path, index: int, entry: Any, defaults: dict, prefix: str,
                overrides: dict[str, Any]) -> Item:
    where = f"{manifest}[material {index + 1}]"
    if not isinstance(entry, dict):
        return Item(f"{prefix}#{index + 1}", where, error=f"{where}: expected a table")
    fields = {k: v for k, v in entry.items() if k not in ENTRY_KEYS}
    ref = entry.get("path")
    name = entry.get("name")
    if name is None and isinstance(ref, str):
        name = Path(ref).with_suffix("").as_posix()
    if not isinstance(name, str) or not NAME_RE.match(name):
        shown = f"#{index + 1}" if name is None else str(name)
        return Item(prefix + shown, where, error=f"{where}: name={name!r} must be letters, digits, "
                    "'.', '_', '-' and '/' separators (a relative output name)")
    where = f"{manifest}[{name}]"
    try:
        merged = dict(defaults)
        if ref is not None:
            if not isinstance(ref, str):
                raise MaterialError(f"{where}: path={ref!r} must be a string")
            merged.update(read_table(manifest.parent / ref))
            where = f"{manifest}[{name}] ({ref})"
        merged.update(fields)
        merged.update(overrides)
        request = parse_request(merged, where)
    except MaterialError as exc:
        return Item(prefix + name, where, error=str(exc))
    return Item(prefix + name, where, request)


def scan_folder(folder: Path, exclude: Iterable[Path] = ()) -> list[Path]:
    """Material files and manifests under ``folder``, recursively, sorted; hidden ones skipped."""
    found = []
    for path in folder.rglob("*"):
        rel = path.relative_to(folder)
        if any(part.startswith(".") for part in rel.parts) or not path.is_file():
            continue
        if path.suffix.lower() not in SUFFIXES:
            continue
        if any(path.resolve().is_relative_to(skip) for skip in exclude):
            continue
        found.append(path)
    return sorted(found, key=lambda p: p.relative_to(folder).as_posix())


def collect(inputs: list[str | Path], overrides: dict[str, Any] | None = None,
            exclude: Iterable[Path] = ()) -> list[Item]:
    """Items for material files, folders of them and manifests, in the order given.

    Names: a file's stem; a folder's files by their path relative to the
    folder without the extension; a manifest's entries by their ``name``.
    A name seen twice fails the second time.
    """
    overrides = overrides or {}
    exclude = [Path(p).resolve() for p in exclude]  # e.g. the output folder, if inside an input
    items: list[Item] = []
    for raw in inputs:
        path = Path(raw)
        if path.is_dir():
            for found in scan_folder(path, exclude):
                items.extend(_file_items(found, found.relative_to(path), overrides))
        elif path.is_file():
            items.extend(_file_items(path, Path(path.name), overrides))
        else:
            items.append(Item(path.stem or str(path), str(path),
                              error=f"{path}: no such file or folder"))
    return _unique(items)


def _file_items(path: Path, rel: Path, overrides: dict[str, Any]) -> list[Item]:
    """The items of one file; ``rel`` is its path below the input folder (or its bare name)."""
    name = rel.with_suffix("").as_posix()
    if path.suffix.lower() not in SUFFIXES:
        return [Item(name, str(path),
                     error=f"{path}: expected a .toml or .json material file or manifest")]
    if is_manifest(path):
        prefix = "" if rel.parent == Path(".") else rel.parent.as_posix() + "/"
        return manifest_items(path, prefix, overrides)
    return material_items(path, name, overrides)


def _unique(items: list[Item]) -> list[Item]:
    seen: dict[str, str] = {}
    for item in items:
        key = item.name.lower()  # case-insensitive file systems would clash too
        if key in seen:
            item.request = None
            item.error = (f"{item.source}: output name {item.name!r} is already used by "
                          f"{seen[key]}")
        else:
            seen[key] = item.source
    return items


def material_schema() -> dict[str, Any]:
    """JSON Schema of a material file (the request model, plus an optional ``$schema`` key)."""
    schema = RenderRequest.model_json_schema()
    schema["title"] = "Opaline material file"
    schema["description"] = (
        "One material for Opaline: a scene preset and any request fields that override its "
        "defaults (docs/materials.md). Written as TOML or JSON; unknown fields are rejected, "
        "and every range is the one the HTTP API accepts."
    )
    schema["properties"] = {SCHEMA_KEY: {"type": "string", "description":
                                         "Optional link to this schema, for editors; ignored."},
                            **schema["properties"]}
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **schema}
