"""`opaline batch --shard K/N` and `opaline batch-merge`: a whole batch split over machines."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from opaline.batch.shard import ShardError, merge_summaries, parse_shard, select, shard_of
from opaline.model.materials import Item
from test_batch import SMALL, make_folder, run_cli, summary_of

NAMES = st.lists(st.from_regex(r"[a-z0-9][a-z0-9/_-]{0,12}", fullmatch=True), unique_by=str.lower,
                 max_size=60)


def items(names: list[str]) -> list[Item]:
    return [Item(name, f"{name}.toml") for name in names]


@given(NAMES, st.integers(1, 7))
def test_shards_cover_the_inputs_once(names, n):
    """The union of the N shards is every input, no input is in two, order is kept."""
    chosen = [[i.name for i in select(items(names), (k, n))] for k in range(1, n + 1)]
    assert sorted(sum(chosen, [])) == sorted(names)
    for part in chosen:
        assert part == [name for name in names if name in part]


@given(NAMES, st.lists(st.from_regex(r"new[a-z0-9]{1,6}", fullmatch=True), min_size=1,
                       max_size=5, unique=True), st.integers(2, 7))
def test_adding_inputs_moves_no_other_input(names, added, n):
    """New inputs (anywhere in the order) join some shard; every old one stays in its own."""
    names = [x for x in names if x not in added]
    before = {i.name: shard_of(i.name, n) for i in items(names)}
    grown = items(added[:1] + names + added[1:])
    after = {i.name: k for k in range(1, n + 1) for i in select(grown, (k, n))}
    assert {name: after[name] for name in names} == before


def test_shards_are_balanced_and_fixed():
    """A hash of the name: about 1/N each, and the same split on every machine and run."""
    names = [f"materials/m{i:04d}" for i in range(2000)]
    sizes = [len(select(items(names), (k, 4))) for k in range(1, 5)]
    assert all(abs(size - 500) < 80 for size in sizes), sizes
    assert [shard_of(name, 4) for name in ("a", "d", "h", "metal/silver", "A")] == [3, 2, 4, 2, 3]


@pytest.mark.parametrize("text", ["0/3", "4/3", "1/0", "1", "a/b", "1/3/4", ""])
def test_malformed_shards_are_refused(text):
    with pytest.raises(ShardError):
        parse_shard(text)


def shard_summary(k: int, n: int, names: list[str], status: str = "rendered") -> dict:
    return {"shard": f"{k}/{n}", "out": f"/shard{k}", "seconds": float(k), "interrupted": False,
            "items": [{"name": x, "input": x, "output": f"/shard{k}/{x}.png", "status": status,
                       "seconds": 0.1, "error": None, "key": x} for x in names]}


def test_merge_wants_every_shard_once():
    parts = [shard_summary(1, 3, ["a"]), shard_summary(2, 3, ["b"]), shard_summary(3, 3, [])]
    merged = merge_summaries(parts[::-1], Path("/all"))
    assert [r["output"] for r in merged["items"]] == ["/all/a.png", "/all/b.png"]
    assert merged["counts"] == {"rendered": 2, "skipped": 0, "failed": 0}
    assert merged["seconds"] == 3.0  # the slowest shard: they run side by side
    for bad, message in ((parts[:2], "missing [3]"), (parts + parts[:1], "repeated [1]"),
                         ([*parts[:2], shard_summary(3, 4, [])], "different shard counts"),
                         ([*parts[:2], shard_summary(3, 3, ["A"])], "in two summaries")):
        with pytest.raises(ShardError, match=message.replace("[", r"\[")):
            merge_summaries(bad, Path("/all"))


MATERIALS = {f"m{i}.toml": f'preset = "cd-rom"\nmu_f = {1 + i / 2}\n' + SMALL.replace("64", "32")
             for i in range(7)}
MATERIALS["sub/bad.toml"] = 'preset = "cd-rom"\nmu_f = 5000\n'


def comparable(summary: dict) -> dict:
    """What must agree between runs: counts and each item but for its timing and folder."""
    def item(record: dict) -> dict:
        out = Path(summary["out"])
        output = record["output"] and Path(record["output"]).relative_to(out).as_posix()
        return {**record, "seconds": None, "output": output}
    return {"counts": summary["counts"],
            "items": sorted((item(r) for r in summary["items"]), key=lambda r: r["name"])}


@pytest.mark.gl
def test_merged_shards_equal_an_unsharded_run(tmp_path, backend):
    """Three shards on three 'machines', outputs copied together and merged: the same summary
    as one unsharded run, and a contact sheet of every item. A material added later joins
    one shard; the other shards' outputs stay up to date."""
    folder = make_folder(tmp_path / "materials", MATERIALS)
    whole = tmp_path / "whole"
    assert run_cli("batch", str(folder), "--out", str(whole), "--backend", backend) == 1
    merged = tmp_path / "merged"
    summaries = []
    for k in (1, 2, 3):
        out = tmp_path / f"shard{k}"
        run_cli("batch", str(folder), "--out", str(out), "--backend", backend, "--shard",
                f"{k}/3")
        assert summary_of(out)["shard"] == f"{k}/3"
        shutil.copytree(out, merged, dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("summary.json"))
        summaries.append(str(out / "summary.json"))
    assert run_cli("batch-merge", *summaries, "--out", str(merged), "--sheet") == 1  # bad.toml
    assert comparable(summary_of(merged)) == comparable(summary_of(whole))
    assert (merged / "sheet.png").is_file() and "m6.png" in (merged / "index.html").read_text()

    (folder / "m7.toml").write_text(MATERIALS["m0.toml"].replace("mu_f = 1.0", "mu_f = 9"))
    for k in (1, 2, 3):
        run_cli("batch", str(folder), "--out", str(tmp_path / f"shard{k}"), "--backend", backend,
                "--shard", f"{k}/3")
        statuses = {r["name"]: r["status"] for r in summary_of(tmp_path / f"shard{k}")["items"]}
        assert {s for name, s in statuses.items() if name != "m7"} <= {"skipped", "failed"}
        assert ("m7" in statuses) == (shard_of("m7", 3) == k)


def test_merge_command_refuses_an_incomplete_set(tmp_path, capsys):
    path = tmp_path / "s1.json"
    path.write_text(json.dumps(shard_summary(1, 2, ["a"])))
    assert run_cli("batch-merge", str(path), "--out", str(tmp_path)) == 2
    assert "missing [2]" in capsys.readouterr().err
