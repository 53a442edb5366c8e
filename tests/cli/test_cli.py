"""The `opaline` command (opaline.cli), run in-process through main()."""

from __future__ import annotations

import math
import os
import re
import typing

import numpy as np
import pytest
from PIL import Image

from opaline.cli import main as cli
from opaline.gl.shaders import ShaderError
from opaline.model import reference
from opaline.model.params import Material, RenderRequest
from opaline.output import files

PRESETS = ("cd-rom", "cd-rom-wide", "cd-rom-ashikhmin", "perturbed-cube", "nacre", "oil-slick",
           "oil-slick-soft", "sphere", "oil-film", "soap-bubble", "cd-rom-grating", "dvd-grating",
           "nacre-film", "anodised-titanium", "tempered-steel", "tempered-copper", "bragg-mirror",
           "morpho", "coated-paint")
# docs/design.md §5 ranges (and exposure, light angles), written out independently of params.py.
RANGES = {
    "ex": (0, 1e6), "ey": (0, 1e6), "mu_f": (0, 1000), "alpha": (0, 1000), "beta": (0, 1000),
    "theta1": (-2 * math.pi, 2 * math.pi), "theta2": (-2 * math.pi, 2 * math.pi),
    "kd": (0, 100), "ks": (0, 100), "albedo": (0, 1), "f0": (0, 1),
    "width": (16, 2048), "height": (16, 2048), "samples": (1, 1024), "wavelengths": (4, 128),
    "exposure": (0, 1000), "light_azimuth": (-360, 360), "light_elevation": (-90, 90),
}
NUMBER = re.compile(r"(-?\d+(?:\.\d+)?(?:e[+-]?\d+)?)(π)?")


def numbers_in(text: str) -> list[float]:
    return [float(n) * (math.pi if pi else 1.0) for n, pi in NUMBER.findall(text.replace("−", "-"))]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def files_under(path) -> list[str]:
    return sorted(str(p.relative_to(path)) for p in path.rglob("*") if p.is_file())


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_render_writes_png_of_requested_size(capsys, tmp_path):
    """`render cd-rom --size 48x32` writes a 48×32 PNG and nothing else."""
    out = tmp_path / "cd.png"
    code, _, err = run(capsys, "render", "cd-rom", "--size", "48x32", "--quality", "draft",
                       "-o", str(out))
    assert code == 0, err
    image = Image.open(out)
    assert image.format == "PNG" and image.size == (48, 32)
    assert np.asarray(image).std() > 0  # a scene, not a blank frame
    assert files_under(tmp_path) == ["cd.png"]


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_render_npy_is_float32_hxwx4(capsys, tmp_path):
    """`--format npy` writes float32 (H, W, 4) linear radiance, finite and non-negative."""
    out = tmp_path / "cd.npy"
    code, _, err = run(capsys, "render", "cd-rom", "--size", "40x24", "--format", "npy",
                       "--quality", "draft", "-o", str(out))
    assert code == 0, err
    data = np.load(out)
    assert data.dtype == np.float32 and data.shape == (24, 40, 4)
    assert np.all(np.isfinite(data)) and np.all(data >= 0.0) and data.max() > 0.0


def test_out_of_range_value_is_one_line(capsys, tmp_path):
    """`--set mu_f=2000` exits 2 with exactly one stderr line naming mu_f, 2000 and the range."""
    out = tmp_path / "x.png"
    code, stdout, err = run(capsys, "render", "cd-rom", "--set", "mu_f=2000", "-o", str(out))
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "mu_f" in lines[0] and "2000" in lines[0] and "[0 … 1000]" in lines[0]
    assert stdout == ""
    assert not out.exists()


def test_malformed_set_is_explained(capsys, tmp_path):
    """`--set nonsense` exits 2 and shows the NAME=VALUE form."""
    out = str(tmp_path / "x.png")
    code, _, err = run(capsys, "render", "cd-rom", "--set", "nonsense", "-o", out)
    assert code == 2
    assert "nonsense" in err and "NAME=VALUE" in err
    assert len(err.strip().splitlines()) == 1


def test_unknown_field_is_explained(capsys, tmp_path):
    """`--set zoom=3` exits 2 naming zoom as unknown and listing real fields."""
    code, _, err = run(capsys, "render", "cd-rom", "--set", "zoom=3", "-o", str(tmp_path / "x.png"))
    assert code == 2
    assert "zoom" in err and "unknown" in err
    assert "mu_f" in err and "theta1" in err


def test_a_second_preset_is_one_line_not_a_traceback(capsys, tmp_path):
    """`render cd-rom --set preset=nacre` raised TypeError (two presets for one request) and
    exited 1 with a traceback; the same preset again is no conflict."""
    out = tmp_path / "x.png"
    code, _, err = run(capsys, "render", "cd-rom", "--set", "preset=nacre", "-o", str(out))
    assert code == 2 and "Traceback" not in err and not out.exists()
    assert "--set preset=nacre" in err and "'cd-rom'" in err and len(err.splitlines()) == 1


def test_an_option_and_a_set_that_disagree_are_refused(capsys, tmp_path):
    """--mesh A beside --set mesh=B drew A without a word (--size and --quality likewise)."""
    out = str(tmp_path / "x.png")
    for argv, said in ((["--mesh", "a.obj", "--set", "mesh=b.obj"], "--mesh and --set mesh=b"),
                       (["--size", "32", "--set", "width=64"], "--size and --set width=64"),
                       (["--quality", "draft", "--set", "quality=high"], "--quality and")):
        code, _, err = run(capsys, "render", "sphere", *argv, "-o", out)
        assert code == 2 and said in err and "give one" in err, err


def test_bad_size_is_explained(capsys, tmp_path):
    """`--size big` exits 2 with the expected form."""
    code, _, err = run(capsys, "render", "cd-rom", "--size", "big", "-o", str(tmp_path / "x.png"))
    assert code == 2 and "WxH" in err


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_unknown_preset_lists_names(capsys, tmp_path):
    """An unknown preset exits 2 with a message listing every preset."""
    code, _, err = run(capsys, "render", "no-such-scene", "-o", str(tmp_path / "x.png"))
    assert code == 2
    assert "no-such-scene" in err
    for name in PRESETS:
        assert name in err


def help_lines(capsys) -> dict[str, str]:
    with pytest.raises(SystemExit) as info:
        cli.main(["render", "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    found = {}
    for line in out.splitlines():
        match = re.match(r"^\s+([a-z_0-9]+)\s{2,}(.*)$", line)
        if match:
            found[match.group(1)] = match.group(2)
    return found


def test_render_help_lists_every_parameter_with_range(capsys):
    """`render --help` has a line per RenderRequest field, with its numeric range."""
    lines = help_lines(capsys)
    for name in RenderRequest.model_fields:
        if name == "preset":
            continue
        assert name in lines, f"{name} missing from --help"
        if name in RANGES:
            lo, hi = RANGES[name]
            stated = numbers_in(lines[name])
            assert any(math.isclose(n, lo, abs_tol=1e-9) for n in stated), (name, lines[name])
            assert any(math.isclose(n, hi, rel_tol=1e-9) for n in stated), (name, lines[name])


def test_render_help_lists_choices(capsys):
    """Choice parameters list their choices in --help."""
    lines = help_lines(capsys)
    for name, info in RenderRequest.model_fields.items():
        literal = next((a for a in typing.get_args(info.annotation)
                        if typing.get_origin(a) is typing.Literal), None)
        if literal is not None:
            for choice in typing.get_args(literal):
                assert choice in lines[name], (name, choice)


def test_presets_lists_all(capsys):
    """`presets` lists the paper's eight presets and the eleven physical ones, one entry each."""
    code, out, _ = run(capsys, "presets")
    assert code == 0
    named = [line.split()[0] for line in out.splitlines() if line and not line[0].isspace()]
    assert sorted(named) == sorted(PRESETS)
    assert "Fig. 9" in out


def test_presets_json(capsys):
    """`presets --json` is JSON keyed by preset name."""
    import json

    code, out, _ = run(capsys, "presets", "--json")
    assert code == 0
    data = json.loads(out)
    assert sorted(data) == sorted(PRESETS)
    assert data["oil-slick"]["defaults"]["alpha"] == 20.0


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_mdf_npy_matches_reference(capsys, tmp_path):
    """`mdf --format npy` equals reference.mdf_plot within 1e-4 of the peak."""
    out = tmp_path / "mdf.npy"
    sets = {"mdf": "multipeak", "mu_f": "8.5", "alpha": "2.0", "beta": "1.2", "theta1": "0.1",
            "theta2": "0.2"}
    argv = ["mdf", "--size", "64", "--format", "npy", "-o", str(out)]
    for key, value in sets.items():
        argv += ["--set", f"{key}={value}"]
    code, _, err = run(capsys, *argv)
    assert code == 0, err
    got = np.load(out)
    expected = reference.mdf_plot(Material(**{k: v for k, v in sets.items()}), 64)
    assert got.shape == (64, 64, 3)
    assert np.abs(got - expected).max() <= 1e-4 * expected.max()


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_mdf_png_is_normalised(capsys, tmp_path):
    """`mdf` (png) writes an N×N image whose brightest value is full white level."""
    out = tmp_path / "mdf.png"
    code, _, err = run(capsys, "mdf", "--size", "32", "--set", "mdf=ashikhmin", "-o", str(out))
    assert code == 0, err
    pixels = np.asarray(Image.open(out))
    assert pixels.shape == (32, 32, 3) and pixels.max() == 255


def test_mdf_bad_material_exits_2(capsys, tmp_path):
    """`mdf --set ex=-1` exits 2 naming ex and its range."""
    code, _, err = run(capsys, "mdf", "--set", "ex=-1", "-o", str(tmp_path / "m.npy"))
    assert code == 2 and "ex" in err and "-1" in err
    assert files_under(tmp_path) == []


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_mdf_refuses_bad_wavelengths(capsys, tmp_path):
    """`mdf --set wavelengths=1` exits 2 naming wavelengths and what is allowed."""
    code, _, err = run(capsys, "mdf", "--size", "16", "--set", "wavelengths=1",
                       "-o", str(tmp_path / "m.npy"))
    assert code == 2 and "wavelengths" in err
    assert files_under(tmp_path) == []


def test_mdf_refuses_non_integer_wavelengths(capsys, tmp_path):
    """`mdf --set wavelengths=many` exits 2 with a one-line message."""
    code, _, err = run(capsys, "mdf", "--set", "wavelengths=many", "-o", str(tmp_path / "m.npy"))
    assert code == 2 and "wavelengths" in err


def failing_render(monkeypatch):
    def boom(self, prepared):
        raise ShaderError("surface.glsl {} failed to compile: test")

    monkeypatch.setattr("opaline.local.pipeline.LocalRenderer.produce", boom)


def failing_replace(monkeypatch):
    def boom(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(files.os, "replace", boom)


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
@pytest.mark.parametrize(
    ("case", "argv", "patch", "expected"),
    [
        ("bad value", ["--set", "mu_f=-3"], None, 2),
        ("unknown preset", [], None, 2),
        ("over budget", ["--quality", "reference", "--size", "2048x2048"], None, 2),
        ("shader failure", [], failing_render, 1),
        ("write failure", [], failing_replace, 1),
    ],
)
def test_no_file_left_when_rendering_fails(capsys, tmp_path, monkeypatch, case, argv, patch,
                                           expected):
    """A failed render leaves neither the output nor a temporary file behind."""
    preset = "nope" if case == "unknown preset" else "cd-rom"
    if patch:
        patch(monkeypatch)
    out = tmp_path / "out.png"
    command = ["render", preset, "--size", "16x16", *argv, "-o", str(out)]
    code, _, err = run(capsys, *command)
    assert code == expected, err
    assert len(err.strip().splitlines()) == 1
    assert files_under(tmp_path) == []


def test_failed_render_keeps_an_existing_file(capsys, tmp_path):
    """A refused request does not touch a file already at the output path."""
    out = tmp_path / "keep.png"
    out.write_bytes(b"old")
    code, _, _ = run(capsys, "render", "cd-rom", "--set", "kd=1000", "-o", str(out))
    assert code == 2
    assert out.read_bytes() == b"old"
    assert files_under(tmp_path) == ["keep.png"]


def test_written_file_respects_umask(tmp_path):
    """Files written by the CLI get the usual 0666 & ~umask mode, like open() would give."""
    umask = os.umask(0o022)
    try:
        files.write_atomic(tmp_path / "a.png", b"data")
        reference_file = tmp_path / "b.png"
        reference_file.write_bytes(b"data")
    finally:
        os.umask(umask)
    assert (tmp_path / "a.png").stat().st_mode & 0o777 == reference_file.stat().st_mode & 0o777
