"""The repository's documents stand on their own: no pointers outside it, no dead links."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Spelled in pieces so that this file does not match itself.
OUTSIDE = ("../" + "shared", "DESIGN" + ".md", "DESIGN" + " §")
# Being rewritten elsewhere; each still cites the old design notes' sections. Once a
# file no longer does, test_exemptions_are_still_needed fails until its line goes.
STALE_FOR_NOW: dict[str, str] = {}
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def tracked_text_files() -> dict[str, str]:
    try:
        listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                                check=True, timeout=30).stdout.decode().split("\0")
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    texts = {}
    for name in filter(None, listed):
        path = ROOT / name
        if not path.is_file():
            continue
        try:
            texts[name] = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue  # images, arrays
    return texts


def test_nothing_points_outside_the_repository():
    """No tracked file points into the folder beside the checkout or to design notes users lack."""
    found = []
    for name, text in tracked_text_files().items():
        for pattern in OUTSIDE:
            if pattern in text and STALE_FOR_NOW.get(name) != pattern:
                line = text[: text.index(pattern)].count("\n") + 1
                found.append(f"{name}:{line}: {pattern!r}")
    assert not found, "refer to docs/design.md instead:\n" + "\n".join(found)


def test_exemptions_are_still_needed():
    """Each exempted file still holds its pattern; a fixed one must leave STALE_FOR_NOW."""
    texts = tracked_text_files()
    fixed = [name for name, pattern in STALE_FOR_NOW.items() if pattern not in texts.get(name, "")]
    assert not fixed, f"no longer needed, remove from STALE_FOR_NOW: {fixed}"


def test_relative_links_in_markdown_resolve():
    """Every relative link in README.md and docs/*.md names a file or folder that exists."""
    dead = []
    for name, text in tracked_text_files().items():
        if not name.endswith(".md") or name.startswith("bench/results/"):
            continue
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path = (ROOT / name).parent / target.split("#", 1)[0]
            if not path.exists():
                dead.append(f"{name}: {target}")
    assert not dead, "dead links:\n" + "\n".join(dead)


def test_every_module_is_in_the_architecture_and_the_readme_layout():
    """docs/architecture.md has a line for every module, and the README's Layout names it."""
    package = ROOT / "service" / "opaline"
    architecture = (ROOT / "docs" / "architecture.md").read_text()
    readme = (ROOT / "README.md").read_text()
    layout = readme[readme.index("## Layout"):]
    missing = []
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        if path.name in ("__init__.py", "__main__.py") or rel.startswith("_"):
            continue
        if rel not in architecture:
            missing.append(f"docs/architecture.md: {rel}")
        if path.name not in layout:
            missing.append(f"README Layout: {rel}")
    assert not missing, "\n".join(missing)
