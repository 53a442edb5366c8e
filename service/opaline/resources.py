"""Where the package's data lives: shader sources and scene presets.

In a checkout they are the top-level ``glsl/`` and ``presets/`` folders; an
installed wheel carries them as ``opaline/_glsl`` and ``opaline/_presets``.
``OPALINE_PRESETS_DIR`` (or ``opaline --presets-dir``) points to a folder of
the user's own presets instead, so adding one never means editing site-packages.
"""

from __future__ import annotations

import hashlib
import os
from functools import cache
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
CHECKOUT = PACKAGE.parent.parent  # service/opaline -> the repository root
PRESETS_ENV = "OPALINE_PRESETS_DIR"


@cache
def glsl_root() -> Path:
    """The shader sources: ``glsl/`` in a checkout, ``opaline/_glsl`` when installed."""
    checkout = CHECKOUT / "glsl"
    if (checkout / "lib").is_dir():
        return checkout
    return PACKAGE / "_glsl"


def builtin_presets_dir() -> Path:
    """``presets/`` in a checkout, ``opaline/_presets`` when installed."""
    checkout = CHECKOUT / "presets"
    if checkout.is_dir() and (CHECKOUT / "glsl" / "lib").is_dir():
        return checkout
    return PACKAGE / "_presets"


def presets_dir() -> Path:
    """The presets in use: ``$OPALINE_PRESETS_DIR`` when set, else the built-in ones."""
    chosen = os.environ.get(PRESETS_ENV)
    return Path(chosen).expanduser() if chosen else builtin_presets_dir()


@cache
def sources_digest() -> str:
    """Hash of every shader source: part of each cache key, so a shader edit invalidates."""
    digest = hashlib.sha256()
    root = glsl_root()
    for path in sorted(root.rglob("*.glsl")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]
