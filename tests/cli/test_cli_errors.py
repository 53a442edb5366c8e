"""The CLI's errors are one line that names the field and its range, as the API's are,
and ``--set`` takes every field the API takes, once."""

from __future__ import annotations

import pytest

from opaline.cli import main as cli
from opaline.cli.args import parse_sets
from opaline.model.params import RenderRequest

TINY = ["--size", "16x16", "--quality", "draft"]


def one_line_error(capsys, *argv: str) -> str:
    code = cli.main(list(argv))
    _, err = capsys.readouterr()
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err  # before: a traceback, or pydantic's first line only
    return lines[0]


@pytest.mark.parametrize("command", ["render", "turntable"])
def test_a_limit_is_one_line(capsys, tmp_path, command, monkeypatch):
    """One line, rc 2, found before a GL context opens (none can be made here)."""
    from opaline.local import pipeline

    monkeypatch.setattr(pipeline, "LocalRenderer", None)  # any use of it fails
    out = tmp_path / ("t.jpg" if command == "render" else "t.webp")
    argv = [command, "cd-rom", *TINY, "--set", "transparent=true", "-o", str(out)]
    if command == "turntable":
        argv += ["--frames", "2", "--set", "format=jpeg"]
    line = one_line_error(capsys, *argv)
    assert "format=jpeg has no alpha channel" in line
    assert not out.exists()


@pytest.mark.parametrize(("flag", "value", "words"), [
    ("--frames", "1", "frames=1 is out of range: allowed [2 … 360]"),
    ("--frames", "400", "frames=400 is out of range: allowed [2 … 360]"),
    ("--fps", "0", "fps=0 is out of range: allowed [1 … 60]"),
])
def test_turntable_ranges_name_the_field(capsys, tmp_path, flag, value, words):
    line = one_line_error(capsys, "turntable", "cd-rom", flag, value,
                          "-o", str(tmp_path / "t.gif"))
    assert words in line


def test_a_parameter_set_twice_is_refused(capsys, tmp_path):
    line = one_line_error(capsys, "render", "cd-rom", "--set", "mu_f=6", "--set", "mu_f=7",
                          "-o", str(tmp_path / "x.png"))
    assert "--set mu_f: given more than once" in line


@pytest.mark.parametrize("name", ["albedo", "metal_f0", "metal_edge_tint", "tangent_axis"])
def test_every_tuple_field_takes_commas(name):
    fields = parse_sets([f"{name}=1,0,0"])
    request = RenderRequest(preset="tempered-steel", metal="artist", **fields)
    assert getattr(request, name) == (1.0, 0.0, 0.0)  # before: metal_f0 "a valid tuple"


@pytest.mark.parametrize(("text", "words"), [
    ('{"preset": "cd-rom", "mu_f": "6"}', "mu_f='6': Input should be a valid number"),
    ('{"preset": "cd-rom", "transparent": "yes"}', "transparent='yes'"),
    ('{"preset": "cd-rom", "width": "64"}', "width='64': Input should be a valid integer"),
    ('{"preset": "cd-rom", "mu_f": 6, "mu_f": 7}', "mu_f: given more than once"),
    ('preset = "cd-rom"\nmu_f = "6"\n', "m.toml:2: mu_f='6'"),
])
def test_a_material_file_is_read_as_the_api_reads_a_body(capsys, tmp_path, text, words):
    """docs/materials.md: a file is the same request POST /v1/render takes; the file took
    strings for numbers and booleans, and the last of a key given twice, where the API
    answers 422."""
    path = tmp_path / ("m.toml" if text.startswith("preset =") else "m.json")
    path.write_text(text)
    line = one_line_error(capsys, "render", str(path), "-o", str(tmp_path / "x.png"))
    assert words in line


def test_a_files_integral_float_and_the_command_lines_strings_are_taken(tmp_path):
    from opaline.model.material_file import load_material

    path = tmp_path / "m.json"
    path.write_text('{"preset": "cd-rom", "width": 64.0, "mu_f": 6}')
    request = load_material(path, parse_sets(["mu_f=7", "transparent=true"]))
    assert (request.width, request.mu_f, request.transparent) == (64, 7.0, True)


@pytest.mark.parametrize(("argv", "words"), [
    (["mdf", "--size", "64", "-o", "m.jpg"], "this command writes png or npy, not jpeg"),
    (["turntable", "cd-rom", "--format", "gif", "-o", "t.webp"],
     "--format gif does not match -o"),
])
def test_a_format_the_output_cannot_hold_is_refused(capsys, tmp_path, argv, words):
    """README: a format that does not match the extension is an error; the MDF plot wrote
    PNG bytes to m.jpg, the turntable a GIF to t.webp."""
    argv = [tmp_path / a if a.endswith((".jpg", ".webp")) else a for a in argv]
    assert words in one_line_error(capsys, *map(str, argv))
    assert list(tmp_path.iterdir()) == []


def test_a_material_files_format_must_fit_the_extension(capsys, tmp_path):
    path = tmp_path / "m.json"
    path.write_text('{"preset": "cd-rom", "format": "npy"}')
    line = one_line_error(capsys, "render", str(path), "-o", str(tmp_path / "x.png"))
    assert "format npy does not match -o" in line  # it wrote an 8-bit PNG
