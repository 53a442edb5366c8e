"""The accuracy table's program lists (service/opaline/model/quality_table.json): each
preset's is every program variant its measurement compiles now, so that its digest
(tests/model/test_auto.py) covers all a shader edit could change in its figures."""

from __future__ import annotations

import pytest

from bench_metrics import load_bench
from opaline.gl.variant_source import variant_label
from opaline.model import auto
from opaline.model.presets import get_preset

accuracy_grid = load_bench("accuracy_grid")


# One preset of each kind of program the table's entries compile: a film under the studio
# with transmission (55 variants: the map's samples a pass follow the samples), a grating
# read by its orders, and the paper's rotation model under its own light. All nineteen took
# 4 min (each variant compiled once), too long for what one shared code path decides;
# bench/accuracy.py lists every preset's when it measures it.
KINDS = ("soap-bubble", "cd-rom-grating", "cd-rom")


@pytest.mark.parametrize("name", KINDS)
def test_table_lists_every_program_the_measurement_compiles(renderer, name):
    """Rendering the preset's grid, every material variant and the references (each
    once, 16²) asks for exactly the variants the table lists: a change to the code that picks
    defines, with no shader edit, still shows."""
    bench = accuracy_grid.Bench(auto.TABLE_SIZE, renderer)
    found = [variant_label(key) for key in accuracy_grid.measured_programs(
        bench, get_preset(name), list(auto.VARIANTS[1:]))]
    assert found == auto.load_table()["presets"][name]["programs"], (
        f"run python bench/accuracy.py --presets {name} --merge-table")


def test_a_points_programs_are_found_once_a_bench(renderer, monkeypatch):
    """A reference's cache key and the table's stamps ask for the same points' programs:
    each point is rendered (16²) to find them once a bench, not once a question."""
    from opaline.model.request import preset_material

    bench = accuracy_grid.Bench(auto.TABLE_SIZE, renderer)
    preset = get_preset("cd-rom")
    material = preset_material(preset)
    rendered = []
    render = renderer.render
    monkeypatch.setattr(renderer, "render",
                        lambda job, *args, **kwargs: rendered.append(job) or render(job, *args, **kwargs))
    first = accuracy_grid.compiled(bench, preset, material, [(4, 8, "none")])
    both = accuracy_grid.compiled(bench, preset, material, [(4, 8, "none"), (2, 8, "none")])
    assert len(rendered) == 2
    assert first and set(first) <= set(both)
