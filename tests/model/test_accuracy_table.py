"""bench/accuracy_table.py and accuracy_merge.py: the program stamps a measurement writes
into the quality table are the labels it measured, in one spelling from the run to the
table, and raw results in another spelling are refused, not mixed in."""

from __future__ import annotations

import argparse
import json

import pytest

from bench_metrics import load_bench
from opaline.gl.variant_source import variant_key
from opaline.model.presets import get_preset
from opaline.model.request import preset_material

accuracy_table = load_bench("accuracy_table")
accuracy_merge = load_bench("accuracy_merge")

LABELS = ["surface.glsl MDF_MULTIPEAK=1 WAVELENGTHS=16",
          "fullscreen.glsl", "surface.glsl MDF_MULTIPEAK=1 WAVELENGTHS=0"]


def measured(programs) -> tuple[list[dict], list[dict], dict]:
    """One preset's run, as bench/accuracy.py's run() gives it: one point, its own material."""
    material = preset_material(get_preset("cd-rom")).model_dump(mode="json")
    rows = [{"preset": "cd-rom", "variant": "base", "samples": 1, "wavelengths": 16,
             "aa": "analytic", "ms": 7.5, "flip": 0.004, "de2000_p95": 0.1}]
    facts = [{"preset": "cd-rom", "variant": "base", "material": material}]
    info = {"size": 128, "programs": {"cd-rom": programs}, "compiled": {"cd-rom": "0123"}}
    return rows, facts, info


def test_the_table_lists_the_labels_the_run_measured():
    entry = accuracy_table.preset_entries(*measured(LABELS))["cd-rom"]
    assert entry["programs"] == sorted(LABELS, key=variant_key)
    assert entry["compiled"] == "0123"


def test_a_last_run_with_programs_in_another_spelling_is_refused(tmp_path, monkeypatch):
    """Raw results whose programs are [name, [[define, value], …]] lists (before the run
    wrote labels) cannot be merged into: --merge stops before the hour of measuring."""
    rows, facts, info = measured([["surface.glsl", [["MDF_MULTIPEAK", 1]]]])
    raw = tmp_path / "accuracy_grid.json"
    raw.write_text(json.dumps({"info": info, "rows": rows, "facts": facts}))
    monkeypatch.setattr(accuracy_merge, "RAW", raw)
    parser = argparse.ArgumentParser()
    with pytest.raises(SystemExit):
        accuracy_merge.last_run(parser, argparse.Namespace(presets=["cd-rom"], size=128))
    info["programs"]["cd-rom"] = LABELS
    raw.write_text(json.dumps({"info": info, "rows": rows, "facts": facts}))
    assert accuracy_merge.last_run(parser, argparse.Namespace(presets=["cd-rom"], size=128))
