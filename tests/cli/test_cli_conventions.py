"""The `opaline` command behaves as users of f3d, ImageMagick and other CLIs expect:
--version, `-o -`, the format from the extension, material files, quiet and verbose,
a presets folder of one's own, budgets from the environment, one-line errors."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opaline import __version__
from opaline.cli import main as cli
from opaline.model.presets import all_presets
from opaline.resources import PRESETS_ENV, builtin_presets_dir

ROOT = Path(__file__).resolve().parents[2]
TINY = ["--size", "16x16", "--quality", "draft"]
gl = pytest.mark.usefixtures("shared_renderer")


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code: int, err: str, status: int = 2) -> str:
    assert code == status, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_version(capsys):
    """`opaline --version` prints "opaline X.Y.Z" and exits 0."""
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"opaline {__version__}\n"


@pytest.mark.gl
@gl
def test_output_dash_writes_the_image_to_stdout(capsysbinary, tmp_path, monkeypatch):
    """`-o -` writes PNG bytes to stdout and creates no file named "-"."""
    monkeypatch.chdir(tmp_path)
    assert cli.main(["render", "cd-rom", *TINY, "-o", "-"]) == 0
    out = capsysbinary.readouterr().out
    assert Image.open(io.BytesIO(out)).size == (16, 16)
    assert list(tmp_path.iterdir()) == []
    assert cli.main(["render", "cd-rom", *TINY, "--format", "npy", "-o", "-"]) == 0
    assert np.load(io.BytesIO(capsysbinary.readouterr().out)).shape == (16, 16, 4)


@pytest.mark.gl
@gl
def test_format_follows_the_extension(capsys, tmp_path):
    """.npy gives npy and .png png without --format; png16 is asked for with --format."""
    assert run(capsys, "render", "cd-rom", *TINY, "-o", str(tmp_path / "a.npy"))[0] == 0
    assert np.load(tmp_path / "a.npy").dtype == np.float32
    assert run(capsys, "render", "cd-rom", *TINY, "-o", str(tmp_path / "a.png"))[0] == 0
    assert Image.open(tmp_path / "a.png").mode == "RGB"
    assert run(capsys, "render", "cd-rom", *TINY, "--format", "png16",
               "-o", str(tmp_path / "b.png"))[0] == 0
    assert (tmp_path / "b.png").read_bytes()[24] == 16  # IHDR bit depth
    assert run(capsys, "mdf", "--size", "16", "-o", str(tmp_path / "m.npy"))[0] == 0
    assert np.load(tmp_path / "m.npy").shape == (16, 16, 3)


@pytest.mark.parametrize("argv, words", [
    (["--format", "npy", "-o", "x.png"], ["--format npy", "x.png", ".npy"]),
    (["--set", "format=npy", "-o", "x.png"], ["npy", "x.png"]),
    (["-o", "x.tiff"], ["x.tiff", "--format"]),
    (["--format", "webp", "-o", "x.jpg"], ["webp", "x.jpg"]),
    (["--format", "png16", "-o", "x.npy"], ["png16", "x.npy"]),
])
def test_format_and_extension_mismatch_is_one_line(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    line = one_line_error(*run(capsys, "render", "cd-rom", *TINY, *argv)[::2])
    assert all(word in line for word in words), line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.gl
@gl
def test_render_a_material_file(capsys, tmp_path):
    """`render FILE.toml` renders the file, the same bytes as the preset with its fields."""
    material = tmp_path / "disc.toml"
    material.write_text('preset = "cd-rom"\nmu_f = 6\nwidth = 24\nheight = 16\n'
                        'quality = "draft"\n')
    assert run(capsys, "render", str(material), "-o", str(tmp_path / "a.png"))[0] == 0
    assert run(capsys, "render", "cd-rom", "--set", "mu_f=6", "--size", "24x16", "--quality",
               "draft", "-o", str(tmp_path / "b.png"))[0] == 0
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    assert run(capsys, "render", str(material), "--set", "mu_f=2",
               "-o", str(tmp_path / "c.png"))[0] == 0
    assert (tmp_path / "c.png").read_bytes() != (tmp_path / "a.png").read_bytes()


def test_material_file_errors_are_one_line(capsys, tmp_path):
    line = one_line_error(*run(capsys, "render", str(tmp_path / "no.json"), "-o", "x.png")[::2])
    assert "no.json: no such material file" in line
    bad = tmp_path / "bad.toml"
    bad.write_text('preset = "cd-rom"\nmuf = 3\n')
    line = one_line_error(*run(capsys, "render", str(bad), "-o", "x.png")[::2])
    assert f"{bad}:2: muf: unknown field, did you mean mu_f?" in line


def test_set_suggests_the_nearest_field(capsys):
    line = one_line_error(*run(capsys, "render", "cd-rom", "--set", "muf=3", "-o", "x.png")[::2])
    assert "muf: unknown field, did you mean mu_f?" in line


@pytest.mark.gl
@gl
def test_mdf_size_takes_n_or_square_wxh(capsys, tmp_path):
    assert run(capsys, "mdf", "--size", "24x24", "-o", str(tmp_path / "m.png"))[0] == 0
    assert Image.open(tmp_path / "m.png").size == (24, 24)
    line = one_line_error(*run(capsys, "mdf", "--size", "64x32", "-o", "m.png")[::2])
    assert "square" in line


@pytest.mark.parametrize("field", ["kd=1", "ks=2", "albedo=1,1,1", "f0=0.5", "quality=draft",
                                   "samples=4", "width=64", "preset=nacre"])
def test_mdf_refuses_fields_that_do_not_change_the_plot(capsys, tmp_path, field):
    """A field the plot ignores is an error naming it, not silently dropped."""
    name = field.split("=")[0]
    line = one_line_error(*run(capsys, "mdf", "--set", field, "-o",
                               str(tmp_path / "m.png"))[::2])
    assert f"--set {name}: does not affect the MDF plot" in line and "mu_f" in line
    assert list(tmp_path.iterdir()) == []


def test_mdf_unknown_field_suggests(capsys):
    line = one_line_error(*run(capsys, "mdf", "--set", "thetaa1=3", "-o", "m.png")[::2])
    assert "unknown field, did you mean theta1?" in line


def test_mdf_help_lists_plot_parameters_and_no_presets(capsys):
    with pytest.raises(SystemExit):
        cli.main(["mdf", "--help"])
    out = capsys.readouterr().out
    assert "preset" not in out.lower()
    for name in ("mdf", "ex", "ey", "mu_f", "alpha", "beta", "theta1", "theta2", "wavelengths"):
        assert f"  {name} " in out, name
    for name in ("kd", "ks", "albedo", "f0", "quality", "samples", "width", "exposure"):
        assert f"  {name} " not in out, name


def test_presets_json_into_a_closed_pipe_is_quiet():
    """`opaline presets --json | head -1`: no BrokenPipeError traceback, exit 0 or 141."""
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the first write: EPIPE every time
    env = {**os.environ, "PYTHONPATH": str(ROOT / "service")}
    result = subprocess.run([sys.executable, "-m", "opaline.cli.main", "presets", "--json"],
                            stdout=write, stderr=subprocess.PIPE, env=env, timeout=60)
    os.close(write)
    assert result.stderr == b""
    assert result.returncode in (0, 141)


@pytest.mark.gl
@gl
@pytest.mark.parametrize("target", ["/proc/opaline.png", "FILE/sub/x.png"])
def test_unwritable_output_is_one_line(capsys, tmp_path, target):
    """An output that cannot be written (no permission, a file where a folder should be)."""
    (tmp_path / "FILE").write_text("a file, not a folder")
    output = target.replace("FILE", str(tmp_path / "FILE"))
    line = one_line_error(*run(capsys, "render", "cd-rom", *TINY, "-o", output)[::2], status=1)
    assert f"cannot write {output}" in line


@pytest.mark.gl
@gl
def test_quiet_and_verbose(capsys, tmp_path):
    """-v logs the resolved job and the timing on stderr; -q prints nothing; either side of
    the sub-command."""
    out = str(tmp_path / "a.png")
    code, stdout, err = run(capsys, "-v", "render", "cd-rom", *TINY, "-o", out)
    assert code == 0 and stdout == ""
    assert "quality=draft samples=1" in err and "16x16" in err and "rendered in" in err
    code, _, err2 = run(capsys, "render", "cd-rom", *TINY, "-o", out, "--verbose")
    assert code == 0 and "rendered in" in err2
    assert run(capsys, "render", "cd-rom", *TINY, "-o", out, "-q") == (0, "", "")
    assert run(capsys, "-q", "mdf", "--size", "16", "-o", str(tmp_path / "m.png")) == (0, "", "")


@pytest.fixture()
def own_presets(tmp_path, monkeypatch):
    """A presets folder of the user's own: one preset copied under a new name."""
    # set, then removed: monkeypatch then unsets it after the test, whatever main() set
    monkeypatch.setenv(PRESETS_ENV, "unset")
    monkeypatch.delenv(PRESETS_ENV)
    folder = tmp_path / "my-presets"
    folder.mkdir()
    text = (builtin_presets_dir() / "cd-rom.toml").read_text()
    (folder / "my-disc.toml").write_text(text.replace('name = "cd-rom"', 'name = "my-disc"'))
    all_presets.cache_clear()
    yield folder
    all_presets.cache_clear()


@pytest.mark.gl
@gl
def test_presets_dir_option_and_environment(capsys, tmp_path, monkeypatch, own_presets):
    """--presets-dir (or $OPALINE_PRESETS_DIR) adds presets without touching site-packages."""
    code, out, err = run(capsys, "--presets-dir", str(own_presets), "presets")
    assert code == 0, err
    assert out.split()[0] == "my-disc" and "cd-rom " not in out
    code, _, err = run(capsys, "render", "my-disc", *TINY, "--presets-dir", str(own_presets),
                       "-o", str(tmp_path / "mine.png"))
    assert code == 0, err
    assert Image.open(tmp_path / "mine.png").size == (16, 16)
    monkeypatch.setenv(PRESETS_ENV, str(own_presets))
    all_presets.cache_clear()
    assert run(capsys, "presets")[1].split()[0] == "my-disc"
    line = one_line_error(*run(capsys, "--presets-dir", str(tmp_path / "nope"), "presets")[::2])
    assert "no such folder" in line
    # The variable naming no folder is said too: it listed no presets and exited 0.
    monkeypatch.setenv(PRESETS_ENV, str(tmp_path / "nope"))
    for argv in (["presets"], ["render", "sphere", *TINY, "-o", str(tmp_path / "x.png")]):
        line = one_line_error(*run(capsys, *argv)[::2])
        assert f"{PRESETS_ENV}=" in line and "no such folder" in line


def test_presets_dir_is_offered_by_the_commands_that_read_presets(capsys):
    for command in ("render", "batch", "presets", "serve", "gallery"):
        with pytest.raises(SystemExit):
            cli.main([command, "--help"])
        assert "--presets-dir" in capsys.readouterr().out, command


@pytest.mark.gl
@gl
def test_cost_budget_from_the_environment(capsys, tmp_path, cost_budget):
    """OPALINE_COST_BUDGET refuses a render over it; raised, the same render goes through."""
    argv = ["render", "cd-rom", "--size", "32x32", "--quality", "draft",
            "-o", str(tmp_path / "a.png")]  # cost 32×32×1×8 = 8192 (draft: 8 wavelengths)
    cost_budget(8000)
    line = one_line_error(*run(capsys, *argv)[::2])
    assert "over the budget of 8000" in line
    line = one_line_error(*run(capsys, "mdf", "--size", "64", "-o", str(tmp_path / "m.png"))[::2])
    assert "over the budget of 8000" in line  # 64×64×3 = 12288
    cost_budget(9000)
    assert run(capsys, *argv)[0] == 0
    assert Image.open(tmp_path / "a.png").size == (32, 32)



def test_an_invalid_setting_is_one_line_naming_the_variable(capsys, tmp_path, cost_budget):
    """OPALINE_COST_BUDGET=abc ends as a usage error that names the variable, its value and
    the rule, not as pydantic's traceback."""
    cost_budget("abc")  # type: ignore[arg-type]
    status, _, err = run(capsys, "render", "cd-rom", "--size", "32x32", "--quality", "draft",
                         "-o", str(tmp_path / "a.png"))
    line = one_line_error(status, err)
    assert status == 2 and "OPALINE_COST_BUDGET='abc'" in line and "integer" in line, line
    assert not (tmp_path / "a.png").exists()
