"""`opaline batch`: right images, honest summaries, incremental re-runs, clean interrupts."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opaline.batch import progress
from opaline.batch import run as batch
from opaline.batch.sheet import THUMB
from opaline.cli.main import main

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[2]
SMALL = 'width = 64\nheight = 64\nquality = "draft"\n'

MIXED = {
    "disc-a.toml": 'preset = "cd-rom"\nmu_f = 6\n' + SMALL,
    "disc-b.toml": 'preset = "cd-rom"\nmu_f = 2\nalpha = 1\nbeta = 5\n' + SMALL,
    "sub/ball.json": json.dumps({"preset": "sphere", "mu_f": 3, "width": 64, "height": 48,
                                 "quality": "draft"}),
    "bad-range.toml": 'preset = "cd-rom"\nmu_f = 5000\n' + SMALL,
    "bad-field.toml": 'preset = "cd-rom"\nmuf = 3\n' + SMALL,
    "bad-preset.json": json.dumps({"preset": "no-such-preset", "width": 64, "height": 64}),
}


def make_folder(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


def run_cli(*args: str) -> int:
    """`opaline ARGS` in this process; the exit status (batch raises SystemExit(1) on failures)."""
    try:
        return main(list(args))
    except SystemExit as exc:
        return int(exc.code or 0)


def summary_of(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def by_name(summary: dict) -> dict[str, dict]:
    return {item["name"]: item for item in summary["items"]}


def pixels(path: Path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"), dtype=np.int16)


@pytest.fixture()
def mixed(tmp_path, backend):
    """A folder of mixed material files, batch-rendered once."""
    folder = make_folder(tmp_path / "materials", MIXED)
    out = tmp_path / "thumbs"
    status = run_cli("batch", str(folder), "--out", str(out), "--backend", backend)
    return folder, out, status


def test_mixed_folder_renders_valid_files_and_exits_nonzero(mixed):
    """Valid files give PNGs of their own size and look; the run still exits 1 for the bad ones."""
    _, out, status = mixed
    assert status == 1
    sizes = {}
    for name in ("disc-a", "disc-b", "sub/ball"):
        with Image.open(out / f"{name}.png") as image:
            assert image.format == "PNG"
            sizes[name] = image.size
        assert (out / f"{name}.png.json").is_file()
    assert sizes == {"disc-a": (64, 64), "disc-b": (64, 64), "sub/ball": (64, 48)}
    a, b = pixels(out / "disc-a.png"), pixels(out / "disc-b.png")
    assert np.abs(a - b).mean() > 1.0, "different materials must give different images"
    assert a.std() > 5, "the image is not a flat colour"
    assert not list(out.glob("bad*")), "no image for an invalid material"


def test_summary_names_each_failure_with_its_reason(mixed):
    """summary.json lists each input: status, output, seconds; failures with field, value, range."""
    _, out, _ = mixed
    summary = summary_of(out)
    items = by_name(summary)
    assert summary["counts"] == {"rendered": 3, "skipped": 0, "failed": 3}
    assert set(items) == {"disc-a", "disc-b", "sub/ball", "bad-range", "bad-field", "bad-preset"}
    assert items["disc-a"]["status"] == "rendered" and items["disc-a"]["seconds"] > 0
    assert items["disc-a"]["output"].endswith("disc-a.png") and items["disc-a"]["error"] is None
    assert "mu_f=5000" in items["bad-range"]["error"]
    assert "[0 … 1000]" in items["bad-range"]["error"]
    assert "bad-range.toml" in items["bad-range"]["error"]
    assert "muf: unknown field" in items["bad-field"]["error"]
    assert "preset='no-such-preset' is not known" in items["bad-preset"]["error"]
    assert all(items[n]["status"] == "failed" and items[n]["output"] is None
               for n in ("bad-range", "bad-field", "bad-preset"))


def test_second_run_renders_nothing(mixed, backend):
    """With nothing changed, every valid input is skipped and no image is rewritten."""
    folder, out, _ = mixed
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*.png")}
    assert run_cli("batch", str(folder), "--out", str(out), "--backend", backend) == 1
    summary = summary_of(out)
    assert summary["counts"] == {"rendered": 0, "skipped": 3, "failed": 3}
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*.png")} == before


def test_changed_file_rerenders_only_itself(mixed, backend):
    """Editing one material re-renders that one image and skips the others."""
    folder, out, _ = mixed
    old = (out / "disc-b.png").read_bytes()
    (folder / "disc-b.toml").write_text('preset = "cd-rom"\nmu_f = 9\n' + SMALL)
    assert run_cli("batch", str(folder), "--out", str(out), "--backend", backend) == 1
    items = by_name(summary_of(out))
    assert items["disc-b"]["status"] == "rendered"
    assert items["disc-a"]["status"] == items["sub/ball"]["status"] == "skipped"
    assert (out / "disc-b.png").read_bytes() != old


def test_image_without_matching_sidecar_rerenders(mixed, backend):
    """An image whose sidecar is missing or holds another key is not up to date."""
    folder, out, _ = mixed
    (out / "disc-a.png.json").unlink()
    (out / "disc-b.png.json").write_text('{"key": "something-else"}')
    run_cli("batch", str(folder), "--out", str(out), "--backend", backend)
    items = by_name(summary_of(out))
    assert items["disc-a"]["status"] == items["disc-b"]["status"] == "rendered"
    assert items["sub/ball"]["status"] == "skipped"
    sidecar = json.loads((out / "disc-a.png.json").read_text())
    assert sidecar["key"] == items["disc-a"]["key"] and sidecar["request"]["mu_f"] == 6


def test_command_line_overrides_size_and_format(tmp_path, backend):
    """--size and --format apply to every material: .npy outputs of the forced size."""
    folder = make_folder(tmp_path / "m", {k: v for k, v in MIXED.items() if "bad" not in k})
    out = tmp_path / "out"
    assert run_cli("batch", str(folder), "--out", str(out), "--size", "32x24", "--format", "npy",
                   "--backend", backend) == 0
    for name in ("disc-a", "disc-b", "sub/ball"):
        array = np.load(out / f"{name}.npy")
        assert array.shape == (24, 32, 4) and array.dtype == np.float32
        assert np.isfinite(array).all() and array.max() > 0


def test_manifest_entries_render_under_their_names(tmp_path, backend):
    """A manifest's inline and path entries become images named after the entries."""
    make_folder(tmp_path, {"disc.toml": 'preset = "cd-rom"\nmu_f = 4\n' + SMALL})
    manifest = tmp_path / "set.manifest.toml"
    manifest.write_text("""
[defaults]
width = 48
height = 48
quality = "draft"

[[material]]
name = "oil/strong"
preset = "oil-slick"

[[material]]
path = "disc.toml"
name = "disc-wide"
width = 80

[[material]]
name = "hot"
mu_f = -3
""")
    out = tmp_path / "out"
    assert run_cli("batch", str(manifest), "--out", str(out), "--backend", backend) == 1
    with Image.open(out / "oil/strong.png") as strong, Image.open(out / "disc-wide.png") as wide:
        assert strong.size == (48, 48) and wide.size == (80, 64)
    items = by_name(summary_of(out))
    assert "set.manifest.toml:16: [hot]: mu_f=-3 is out of range" in items["hot"]["error"]


def test_sheet_writes_an_index_and_a_grid_image(mixed, backend):
    """--sheet writes index.html (thumbnails, names, failures with reasons) and sheet.png."""
    folder, out, _ = mixed
    run_cli("batch", str(folder), "--out", str(out), "--sheet", "--backend", backend)
    page = (out / "index.html").read_text()
    for name in ("disc-a", "disc-b", "sub/ball"):
        assert f'<img src="{name}.png"' in page
    assert "Failed (3)" in page and "mu_f=5000 is out of range" in page
    with Image.open(out / "sheet.png") as sheet:
        assert sheet.format == "PNG"
        grid = np.asarray(sheet.convert("RGB"))
    columns = 3  # ceil(sqrt(6))
    assert grid.shape[1] == columns * (THUMB + 8) and grid.shape[0] >= 2 * THUMB
    assert grid.std() > 10, "the sheet holds pictures, not one colour"


def test_missing_input_fails_alone(tmp_path, backend):
    """A path that does not exist fails in the summary; the other inputs still render."""
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"]})
    out = tmp_path / "out"
    assert run_cli("batch", str(tmp_path / "nope.toml"), str(folder / "disc-a.toml"),
                   "--out", str(out), "--backend", backend) == 1
    items = by_name(summary_of(out))
    assert "no such file" in items["nope"]["error"] and items["disc-a"]["status"] == "rendered"


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_an_output_that_cannot_be_written_fails_alone(tmp_path, backend, jobs):
    """A folder where one image goes: that item fails in the summary, the others render.
    Before, the batch stopped at it with no summary (and with --jobs 2 rendered nothing)."""
    folder = make_folder(tmp_path / "m", {name: MIXED["disc-a.toml"]
                                          for name in ("ball.toml", "disc-a.toml", "disc-b.toml")})
    out = tmp_path / "out"
    (out / "disc-a.png").mkdir(parents=True)
    assert run_cli("batch", str(folder), "--out", str(out), "--backend", backend,
                   "--jobs", jobs) == 1
    items = by_name(summary_of(out))
    assert "cannot write" in items["disc-a"]["error"] and "is a directory" in items["disc-a"]["error"]
    assert items["ball"]["status"] == items["disc-b"]["status"] == "rendered"


def test_out_that_is_a_file_is_a_usage_error(tmp_path, capsys):
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"]})
    (tmp_path / "taken").write_text("")
    status, _, err = run_captured(capsys, "batch", str(folder), "--out", str(tmp_path / "taken"))
    assert status == 2 and "not a folder" in err


def test_two_worker_processes_give_the_same_bytes_as_one(tmp_path, backend):
    """--jobs 2 (spawned processes, a context each) renders byte-identical images to --jobs 1."""
    folder = make_folder(tmp_path / "m", {k: v for k, v in MIXED.items() if "bad" not in k})
    one, two = tmp_path / "one", tmp_path / "two"
    assert run_cli("batch", str(folder), "--out", str(one), "--backend", backend) == 0
    assert run_cli("batch", str(folder), "--out", str(two), "--jobs", "2",
                   "--backend", backend) == 0
    for name in ("disc-a.png", "disc-b.png", "sub/ball.png"):
        assert (one / name).read_bytes() == (two / name).read_bytes()
    assert summary_of(two)["jobs"] == 2


def test_plain_progress_in_ci_and_off_a_terminal():
    """The rich bar is used only on a terminal and never when CI=true."""

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    assert progress.use_rich(Tty(), {}) is True
    assert progress.use_rich(Tty(), {"CI": "true"}) is False
    assert progress.use_rich(io.StringIO(), {}) is False


def test_rich_progress_reports_failures_and_finishes(tmp_path, backend):
    """The rich reporter runs a whole batch and prints each failure above its bar."""
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"],
                                          "bad-range.toml": MIXED["bad-range.toml"]})
    stream = io.StringIO()
    options = batch.Options(out=tmp_path / "out", backend=backend)
    reporter = progress.RichProgress(stream, errors=stream)  # a terminal: both on stderr
    summary = batch.run_batch([folder], options, progress=reporter)
    assert summary["counts"] == {"rendered": 1, "skipped": 0, "failed": 1}
    text = stream.getvalue()
    assert "failed: " in text and "bad-range.toml:2: mu_f=5000" in text
    assert "rendering" in text and "1/1" in text


def test_plain_progress_lines_show_rate_and_eta(mixed, backend, capsys):
    """Off a terminal each rendered image is one line with its rate and ETA."""
    folder, out, _ = mixed
    capsys.readouterr()
    run_cli("batch", str(folder), "--out", str(out), "--force", "--backend", backend)
    text = capsys.readouterr().out
    assert "[1/3] rendered" in text and "/s, ETA" in text
    assert "3 rendered, 0 skipped, 3 failed" in text


# In CI: failures on stderr, a JUnit report, GitHub annotations, pruning.

TINY = 'width = 16\nheight = 16\nquality = "draft"\n'
CI_FILES = {
    "good.toml": 'preset = "cd-rom"\n' + TINY,
    "typo.toml": 'preset = "cd-rom"\nmuf = 3\n' + TINY,
    "sub/lost.json": '{\n  "preset": "no-such-preset",\n  "width": 16\n}\n',
}


def run_captured(capsys, *args: str) -> tuple[int, str, str]:
    status = run_cli(*args)
    out, err = capsys.readouterr()
    return status, out, err


def test_failures_are_one_line_each_on_stderr_with_file_and_line(tmp_path, backend, capsys):
    """Each failed material is one stderr line naming its file:line and the reason."""
    folder = make_folder(tmp_path / "m", CI_FILES)
    status, out, err = run_captured(capsys, "batch", str(folder), "--out", str(tmp_path / "o"),
                                    "--backend", backend)
    assert status == 1
    failed = [line for line in err.splitlines() if line.startswith("failed: ")]
    assert len(failed) == 2 and len(err.strip().splitlines()) == 2, err
    assert any(f"{folder / 'typo.toml'}:2: muf: unknown field, did you mean mu_f?" in line
               for line in failed), failed
    assert any(f"{folder / 'sub/lost.json'}:2: preset='no-such-preset'" in line
               for line in failed), failed
    assert "failed:" not in out


def test_junit_report_has_a_case_per_material(tmp_path, backend, capsys):
    """--report junit FILE: well-formed XML, one testcase per material, failures with reasons."""
    from xml.etree import ElementTree

    folder = make_folder(tmp_path / "m", CI_FILES)
    report = tmp_path / "reports" / "batch.xml"
    status, _, _ = run_captured(capsys, "batch", str(folder), "--out", str(tmp_path / "o"),
                                "--backend", backend, "--report", "junit", str(report))
    assert status == 1
    suite = ElementTree.parse(report).getroot().find("testsuite")
    assert suite is not None and suite.get("tests") == "3" and suite.get("failures") == "2"
    cases = {case.get("name"): case for case in suite.iter("testcase")}
    assert set(cases) == {"good", "typo", "sub/lost"}
    assert cases["good"].find("failure") is None
    failure = cases["typo"].find("failure")
    assert failure is not None and "did you mean mu_f?" in failure.get("message")
    assert cases["typo"].get("file") == str(folder / "typo.toml")
    assert cases["typo"].get("line") == "2"
    assert "no-such-preset" in cases["sub/lost"].find("failure").get("message")


def test_unknown_report_kind_is_a_usage_error(tmp_path, capsys):
    status, _, err = run_captured(capsys, "batch", str(tmp_path), "--out", str(tmp_path / "o"),
                                  "--report", "xunit", "r.xml")
    assert status == 2 and "unknown report kind" in err


@pytest.mark.parametrize("actions", ["true", None])
def test_github_annotations_only_on_github_actions(tmp_path, backend, capsys, monkeypatch,
                                                   actions):
    """GITHUB_ACTIONS=true: an ::error annotation per failure, at its file and line."""
    if actions:
        monkeypatch.setenv("GITHUB_ACTIONS", actions)
    else:
        monkeypatch.delenv("GITHUB_ACTIONS", raising=False)
    folder = make_folder(tmp_path / "m", CI_FILES)
    _, out, _ = run_captured(capsys, "batch", str(folder), "--out", str(tmp_path / "o"),
                             "--backend", backend)
    annotations = [line for line in out.splitlines() if line.startswith("::error ")]
    if not actions:
        assert annotations == []
        return
    assert len(annotations) == 2
    typo = next(a for a in annotations if "typo.toml" in a)
    props, message = typo.removeprefix("::error ").split("::", 1)
    assert props.startswith(f"file={folder / 'typo.toml'},line=2,title=")
    assert "did you mean mu_f?" in message and "\n" not in message


def test_no_material_found_is_a_usage_error(tmp_path, capsys):
    """An input folder without material files exits 2 with one line, not "0 rendered"."""
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("no materials here")
    status, _, err = run_captured(capsys, "batch", str(tmp_path / "empty"), "--out",
                                  str(tmp_path / "o"))
    assert status == 2
    assert len(err.strip().splitlines()) == 1 and "no material files" in err


def test_empty_material_file_fails_instead_of_rendering_a_sphere(tmp_path, backend, capsys):
    folder = make_folder(tmp_path / "m", {"empty.toml": ""})
    status, _, err = run_captured(capsys, "batch", str(folder), "--out", str(tmp_path / "o"),
                                  "--backend", backend)
    assert status == 1 and "empty material file" in err
    assert not (tmp_path / "o" / "empty.png").exists()


def test_prune_removes_outputs_of_materials_that_are_gone(tmp_path, backend, capsys):
    """--prune deletes the image and sidecar of a removed material, and nothing else."""
    folder = make_folder(tmp_path / "m", {"a.toml": CI_FILES["good.toml"],
                                          "sub/b.toml": CI_FILES["good.toml"],
                                          "bad.toml": 'preset = "cd-rom"\nmu_f = -1\n'})
    out = tmp_path / "o"
    assert run_captured(capsys, "batch", str(folder), "--out", str(out), "--backend",
                        backend)[0] == 1
    (out / "mine.png").write_bytes(b"a user's file, no sidecar")
    (folder / "sub" / "b.toml").unlink()
    run_captured(capsys, "batch", str(folder), "--out", str(out), "--backend", backend)
    assert (out / "sub" / "b.png").is_file(), "without --prune nothing is removed"
    run_captured(capsys, "batch", str(folder / "typo"), "--out", str(out), "--prune",
                 "--backend", backend)  # a missing input: no pruning at all
    assert (out / "a.png").is_file() and (out / "sub" / "b.png").is_file()
    status, _, _ = run_captured(capsys, "batch", str(folder), "--out", str(out), "--prune",
                                "--backend", backend)
    assert status == 1  # bad.toml still fails, and still exists: nothing of it is pruned
    assert files_in(out) == ["a.png", "a.png.json", "mine.png", "summary.json"]
    assert sorted(summary_of(out)["pruned"]) == [str(out / "sub/b.png"),
                                                 str(out / "sub/b.png.json")]


def files_in(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def test_unwritable_out_folder_is_one_line(tmp_path, backend, capsys):
    """--out where nothing can be written: exit 1 and one line, never a traceback."""
    folder = make_folder(tmp_path / "m", {"good.toml": CI_FILES["good.toml"]})
    status, _, err = run_captured(capsys, "batch", str(folder), "--out", "/proc/opaline-thumbs",
                                  "--backend", backend)
    assert status == 1
    assert err.strip().splitlines() == ["opaline batch: error: /proc/opaline-thumbs: "
                                        "No such file or directory"]


def test_quiet_batch_prints_only_failures(tmp_path, backend, capsys, monkeypatch):
    """-q: no progress and no summary line; the failure lines stay on stderr."""
    monkeypatch.delenv("GITHUB_ACTIONS", raising=False)  # annotations are failures: they stay
    folder = make_folder(tmp_path / "m", CI_FILES)
    status, out, err = run_captured(capsys, "-q", "batch", str(folder), "--out",
                                    str(tmp_path / "o"), "--backend", backend)
    assert status == 1 and out == ""
    assert len(err.strip().splitlines()) == 2 and err.startswith("failed: ")


# Interrupts: a real process, a real signal.

HEAVY = 'preset = "cd-rom"\nmu_f = {mu}\nwidth = 384\nheight = 384\nsamples = 16\n'


def start_batch(folder: Path, out: Path, jobs: int, backend: str) -> subprocess.Popen:
    env = {**os.environ, "CI": "true"}
    # As from a terminal: Ctrl-C's default disposition. A child inherits an ignored SIGINT
    # (a background job's, or one a test in this process left ignored), and Python then
    # installs no KeyboardInterrupt for it: the run would ignore the signal and finish.
    return subprocess.Popen(
        [sys.executable, "-m", "opaline.cli.main", "batch", str(folder), "--out", str(out),
         "--jobs", str(jobs), "--backend", backend],
        cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def interrupt_after_first_image(process: subprocess.Popen, out: Path, sig: int) -> str:
    deadline = time.monotonic() + 60
    while not list(out.glob("*.png")):
        assert process.poll() is None, process.communicate()[0]
        assert time.monotonic() < deadline, "no image appeared"
        time.sleep(0.01)
    process.send_signal(sig)
    return process.communicate(timeout=60)[0]


def assert_no_partial_files(out: Path) -> list[Path]:
    leftovers = [p for p in out.rglob("*") if p.name.startswith(".") or p.suffix == ".tmp"]
    assert not leftovers, leftovers
    images = sorted(out.glob("*.png"))
    for path in images:
        with Image.open(path) as image:
            image.load()  # a truncated PNG raises here
    return images


@pytest.mark.parametrize("sig, jobs", [(signal.SIGINT, 2), (signal.SIGTERM, 1)],
                         ids=["sigint-2-processes", "sigterm-1-thread"])
def test_interrupt_leaves_no_partial_file_and_a_rerun_finishes(tmp_path, backend, sig, jobs):
    """A signal mid-run exits 130 with only complete images; the next run renders the rest."""
    total = 16
    folder = make_folder(tmp_path / "m", {f"m{i:02d}.toml": HEAVY.format(mu=i + 1)
                                          for i in range(total)})
    out = tmp_path / "out"
    process = start_batch(folder, out, jobs, backend)
    log = interrupt_after_first_image(process, out, sig)
    assert process.returncode == 130, log
    assert "interrupted" in log
    images = assert_no_partial_files(out)
    assert 1 <= len(images) < total, "the run stopped midway"
    summary = summary_of(out)
    assert summary["interrupted"] is True and summary["counts"]["interrupted"] > 0
    complete = [p for p in images if p.with_name(p.name + ".json").is_file()]
    time.sleep(0.2)
    assert not [p for p in out.rglob("*") if p.suffix == ".tmp"], "a worker wrote after the stop"
    if sig == signal.SIGINT:
        rerun = start_batch(folder, out, 1, backend)
        rerun.communicate(timeout=120)
        assert rerun.returncode == 0
        counts = summary_of(out)["counts"]
        assert counts == {"rendered": total - len(complete), "skipped": len(complete),
                          "failed": 0}
        assert len(assert_no_partial_files(out)) == total


def interrupt_rename(monkeypatch, suffix: str) -> None:
    """Make the first rename onto a name ending in ``suffix`` look like a Ctrl-C arriving then."""
    real = os.replace

    def replace(src, dst):
        if str(dst).endswith(suffix):
            monkeypatch.setattr(os, "replace", real)
            raise KeyboardInterrupt
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)


def test_interrupt_during_a_write_leaves_neither_image_nor_temp_file(tmp_path, backend,
                                                                     monkeypatch):
    """Images are renamed into place: a Ctrl-C before the rename leaves no image, no temp file."""
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"]})
    options = batch.Options(out=tmp_path / "out", backend=backend)
    interrupt_rename(monkeypatch, "disc-a.png")
    with pytest.raises(KeyboardInterrupt):
        batch.run_batch([folder], options, progress=progress.PlainProgress(io.StringIO()))
    assert sorted(p.name for p in options.out.iterdir()) == ["summary.json"]
    summary = summary_of(options.out)
    assert summary["interrupted"] and by_name(summary)["disc-a"]["status"] == "interrupted"


def test_sidecar_is_written_after_the_image(tmp_path, backend, monkeypatch):
    """Cut between a changed image and its sidecar, the next run still re-renders the image."""
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"]})
    options = batch.Options(out=tmp_path / "out", backend=backend)
    quiet = progress.PlainProgress(io.StringIO())
    batch.run_batch([folder], options, progress=quiet)
    old = (options.out / "disc-a.png").read_bytes()
    (folder / "disc-a.toml").write_text('preset = "cd-rom"\nmu_f = 12\n' + SMALL)
    interrupt_rename(monkeypatch, "disc-a.png")
    with pytest.raises(KeyboardInterrupt):
        batch.run_batch([folder], options, progress=quiet)
    assert (options.out / "disc-a.png").read_bytes() == old, "the old image is untouched"
    summary = batch.run_batch([folder], options, progress=quiet)
    assert by_name(summary)["disc-a"]["status"] == "rendered"
    assert (options.out / "disc-a.png").read_bytes() != old


@pytest.mark.parametrize("option, message", [
    (["--size", "8x8"], "width=8 is out of range: allowed [16 … 2048]"),
    (["--size", "big"], "expected WxH"),
    (["--server", "localhost:8000"], "expected an http:// or https:// URL"),
    (["--jobs", "0"], "--jobs=0 is out of range"),
    (["--retries", "-1"], "--retries=-1 is out of range: allowed [0 … 100]"),
])
def test_bad_options_are_usage_errors(tmp_path, capsys, option, message):
    """A bad command-line option fails once, with status 2, before anything renders."""
    folder = make_folder(tmp_path / "m", {"disc-a.toml": MIXED["disc-a.toml"]})
    assert run_cli("batch", str(folder), "--out", str(tmp_path / "out"), *option) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.gl
def test_a_second_batch_of_a_folder_passes_over_the_first_ones_outputs(tmp_path, backend):
    """`batch . --out thumbs` then `batch . --out thumbs2`: the second read thumbs/'s
    sidecars and summary as material files, failed them and exited 1. An earlier batch's
    output folder, and its sidecars wherever a --summary elsewhere left them, are skipped."""
    make_folder(tmp_path, {"a.toml": 'preset = "cd-rom"\n' + SMALL})
    first = tmp_path / "thumbs"
    assert run_cli("batch", str(tmp_path), "--out", str(first), "--backend", backend) == 0
    apart = tmp_path / "apart"
    assert run_cli("batch", str(tmp_path), "--out", str(apart), "--summary",
                   str(tmp_path / "elsewhere.txt"), "--backend", backend) == 0
    again = tmp_path / "thumbs2"
    assert run_cli("batch", str(tmp_path), "--out", str(again), "--backend", backend) == 0
    assert sorted(by_name(summary_of(again))) == ["a"]
    # A summary written among the inputs excludes itself, not the folder it is in: the
    # second run found "no material files" in the input itself.
    beside = tmp_path / "summary.json"
    for _ in range(2):
        assert run_cli("batch", str(tmp_path), "--out", str(tmp_path / "renders"),
                       "--summary", str(beside), "--backend", backend) == 0
    assert sorted(item["name"] for item in json.loads(beside.read_text())["items"]) == ["a"]
