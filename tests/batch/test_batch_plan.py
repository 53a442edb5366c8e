"""A batch's plan on disk: sidecars decide what is up to date; stray temporaries are removed."""

from __future__ import annotations

from opaline.batch.plan import Task, plan, remove_temporaries, up_to_date, write_result
from opaline.model.materials import Item
from opaline.model.params import RenderRequest


def planned(tmp_path, name: str = "disc", **fields) -> Task:
    request = RenderRequest(preset="cd-rom", width=64, height=64, **fields)
    (task,) = plan([Item(name, f"{name}.toml", request)], tmp_path)
    return task


def test_output_is_current_only_with_its_own_key(tmp_path):
    """An output is up to date once written with its sidecar, and not for another request."""
    task = planned(tmp_path)
    assert task.status == "pending" and task.output == tmp_path / "disc.png"
    write_result(task, b"image")
    assert up_to_date(task)
    assert planned(tmp_path).status == "skipped"
    assert planned(tmp_path, mu_f=3).status == "pending"
    task.sidecar.write_text("[1, 2]")  # JSON, but not an object
    assert not up_to_date(task)


def test_over_budget_fails_in_the_plan_unless_a_server_checks(tmp_path):
    """Over the local cost budget fails with the numbers; without a budget it is planned."""
    item = Item("big", "big.toml", RenderRequest(preset="cd-rom", width=2048, height=2048,
                                                 samples=1024))
    (local,) = plan([item], tmp_path, cost_budget=2048 * 2048 * 64 * 3)
    (remote,) = plan([item], tmp_path)
    assert local.status == "failed" and "is over the budget" in local.error
    assert remote.status == "pending"


def test_temporaries_of_names_with_glob_characters_are_removed(tmp_path):
    """Names are matched literally: '[1]' in a name is not a character class."""
    task = planned(tmp_path, name="disc[1]")
    stray = tmp_path / ".disc[1].png.abc123.tmp"
    stray.write_bytes(b"partial")
    other = tmp_path / ".disc1.png.abc123.tmp"
    other.write_bytes(b"someone else's")
    remove_temporaries([task], [])
    assert not stray.exists() and other.exists()
