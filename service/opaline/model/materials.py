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

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opaline.model.manifest_lines import entry_lines
from opaline.model.material_file import (
    SCHEMA_KEY,
    SUFFIXES,
    MaterialError,
    files_beside,
    load_material,
    parse_request,
    read_table,
    read_text_table,
)
from opaline.model.params import RenderRequest

__all__ = ["Item", "MaterialError", "collect", "load_material", "material_schema"]

MANIFEST_SUFFIXES = (".manifest.toml", ".manifest.json")
# An output name: every segment starts with a letter or digit, so no "..", no hidden
# file and no absolute path can escape the output folder.
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*(/[A-Za-z0-9][A-Za-z0-9._-]*)*$")
MANIFEST_KEYS = {"defaults", "material"}
ENTRY_KEYS = {"name", "path"}


@dataclass
class Item:
    """One thing to render: a stable output name, where it came from, and the request or why not.

    ``file`` and ``line`` locate a failure for CI annotations (line None when unknown)."""

    name: str
    source: str
    request: RenderRequest | None = None
    error: str | None = None
    file: str | None = None
    line: int | None = None


def is_manifest(path: Path) -> bool:
    return path.name.lower().endswith(MANIFEST_SUFFIXES)


def failed(name: str, source: str, exc: MaterialError, file: Path | str) -> Item:
    """An item for a MaterialError, keeping its file and line."""
    return Item(name, source, error=str(exc), file=exc.path or str(file), line=exc.line)


def material_items(path: Path, name: str, overrides: dict[str, Any]) -> list[Item]:
    try:
        return [Item(name, str(path), load_material(path, overrides), file=str(path))]
    except MaterialError as exc:
        return [failed(name, str(path), exc, path)]


def manifest_items(path: Path, prefix: str, overrides: dict[str, Any]) -> list[Item]:
    """Every entry of a manifest; entry names are prefixed with ``prefix``."""
    try:
        data, text = read_text_table(path)
        entries, defaults = _manifest_parts(path, data)
    except MaterialError as exc:
        return [failed(prefix + path.name.split(".")[0], str(path), exc, path)]
    defaults = files_beside(path, defaults)
    lines = entry_lines(text, path.suffix.lower() == ".json")
    if len(lines) != len(entries):  # written in a form not scanned for: no lines
        lines = []
    return [_entry_item(path, index, entry, defaults, prefix, overrides,
                        lines[index] if lines else None)
            for index, entry in enumerate(entries)]


def _manifest_parts(path: Path, data: dict[str, Any]) -> tuple[list[Any], dict[str, Any]]:
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


def _entry_item(manifest: Path, index: int, entry: Any, defaults: dict[str, Any], prefix: str,
                overrides: dict[str, Any], line: int | None) -> Item:
    """Entry ``index`` of a manifest, written from ``line`` (None: not known); its errors
    start ``FILE:LINE:`` as a material file's do, for editors and CI annotations."""
    def at_entry(label: str) -> str:
        return f"{manifest}: [{label}]" if line is None else f"{manifest}:{line}: [{label}]"

    where = at_entry(f"material {index + 1}")
    if not isinstance(entry, dict):
        kind = "an object" if manifest.suffix.lower() == ".json" else "a table"
        return Item(f"{prefix}#{index + 1}", where, error=f"{where}: expected {kind}, got "
                    f"{entry!r:.40}", file=str(manifest), line=line)
    fields = {k: v for k, v in entry.items() if k not in ENTRY_KEYS}
    ref = entry.get("path")
    name = entry.get("name")
    if name is None and isinstance(ref, str):
        name = Path(ref).with_suffix("").as_posix()
    if not isinstance(name, str) or not NAME_RE.match(name):
        shown = f"#{index + 1}" if name is None else str(name)
        return Item(prefix + shown, where, error=f"{where}: name={name!r} must be letters, digits, "
                    "'.', '_', '-' and '/' separators (a relative output name)",
                    file=str(manifest), line=line)
    where = at_entry(name)
    try:
        merged = dict(defaults)
        if ref is not None:
            if not isinstance(ref, str):
                raise MaterialError(f"{where}: path={ref!r} must be a string")
            if not (manifest.parent / ref).is_file():  # the entry's mistake, at its line
                raise MaterialError(f"{where}: path={ref!r}: no such material file beside "
                                    "the manifest")
            table = read_table(manifest.parent / ref)
            if not table:
                raise MaterialError(f"{where}: {ref} is an empty material file",
                                    manifest.parent / ref)
            merged.update(files_beside(manifest.parent / ref, table))
            where = f"{at_entry(name)} ({ref})"
        merged.update(files_beside(manifest, fields))
        merged.update(overrides)
        request = parse_request(merged, where, lax=overrides)
    except MaterialError as exc:
        item = failed(prefix + name, where, exc, manifest)
        if item.line is None and item.file == str(manifest):
            item.line = line
        return item
    return Item(prefix + name, where, request, file=str(manifest))


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
                              error=f"{path}: no such file or folder", file=str(path)))
    return _unique(items)


def _file_items(path: Path, rel: Path, overrides: dict[str, Any]) -> list[Item]:
    """The items of one file; ``rel`` is its path below the input folder (or its bare name)."""
    name = rel.with_suffix("").as_posix()
    if path.suffix.lower() not in SUFFIXES:
        return [Item(name, str(path), file=str(path),
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
