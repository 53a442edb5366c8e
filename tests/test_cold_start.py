"""A cold ``opaline render`` loads only what a render needs (docs/speed.md, "Cold start").

Timings live in bench/speed.py; here, what they rest on: which modules the command
imports, and settings that mean the same read lightly or through the class.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from opaline.setting_defaults import DEFAULT_COST_BUDGET, DEFAULTS
from opaline.settings import Settings, SettingsError, get_settings, setting

# Each cost a cold draft render 5-40 ms and none is needed by one.
NOT_IMPORTED = ("pydantic_settings", "opaline.service_settings", "pyrr", "PIL", "numpy.ma",
                "pygltflib")


@pytest.mark.gl
def test_a_cold_render_imports_neither_settings_class_nor_pillow(backend, tmp_path):
    out = tmp_path / "sphere.png"
    env = {k: v for k, v in os.environ.items() if not k.lower().startswith("opaline_")}
    result = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "opaline", "render", "sphere", "--quality",
         "draft", "--size", "32", "--backend", backend, "-q", "-o", str(out)],
        env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    imported = {line.rpartition("|")[2].strip() for line in result.stderr.splitlines()
                if line.startswith("import time:")}
    assert "opaline.gl.renderer" in imported  # the trace is the command's
    assert not [m for m in imported if m.split(".")[0] in NOT_IMPORTED or m in NOT_IMPORTED]
    with Image.open(out) as image:
        assert image.size == (32, 32) and np.asarray(image).std() > 0


def test_light_defaults_are_the_class_defaults():
    for name, value in DEFAULTS.items():
        assert Settings.model_fields[name].default == value


@pytest.fixture
def clean_environment(monkeypatch):
    for key in list(os.environ):
        if key.lower().startswith("opaline_"):
            monkeypatch.delenv(key)
    get_settings.cache_clear()
    yield monkeypatch
    get_settings.cache_clear()


def test_setting_without_opaline_variables_skips_the_class(clean_environment):
    assert setting("cost_budget") == DEFAULT_COST_BUDGET
    assert setting("environments_dir") is None
    assert get_settings.cache_info().currsize == 0  # nothing was built
    assert setting("port") == 8000  # not a render setting: read through the class
    assert get_settings.cache_info().currsize == 1


def test_setting_reads_what_the_class_reads(clean_environment):
    clean_environment.setenv("opaline_cost_budget", "1234")  # any case, as pydantic-settings
    assert setting("cost_budget") == 1234 == get_settings().cost_budget
    get_settings.cache_clear()
    clean_environment.delenv("opaline_cost_budget")
    clean_environment.setenv("OPALINE_PORT", "not a port")  # another setting, invalid
    with pytest.raises(SettingsError, match="OPALINE_PORT='not a port': Input should be"):
        setting("cost_budget")


def test_built_settings_are_what_setting_answers(clean_environment):
    """Once something built the settings (a test, a service), they are what is read."""
    get_settings.cache_clear()
    clean_environment.setenv("OPALINE_COST_BUDGET", "99")
    get_settings()
    clean_environment.delenv("OPALINE_COST_BUDGET")
    assert setting("cost_budget") == 99
