"""A non-editable install carries the shaders and presets it needs."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_wheel_contains_every_shader_and_preset(tmp_path):
    """The built wheel ships glsl/ as opaline/_glsl and presets/ as opaline/_presets."""
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(tmp_path), str(ROOT)],
        check=True, capture_output=True,
    )
    wheel = next(tmp_path.glob("opaline-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for source in (ROOT / "glsl").rglob("*.glsl"):
        assert f"opaline/_glsl/{source.relative_to(ROOT / 'glsl').as_posix()}" in names
    for preset in (ROOT / "presets").glob("*.toml"):
        assert f"opaline/_presets/{preset.name}" in names
    assert any(name.endswith("entry_points.txt") for name in names)
    assert "opaline/model/quality_table.json" in names  # quality=auto's measurements
