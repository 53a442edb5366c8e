"""Scene presets (opaline.model.presets): the files load, match the paper, and fail clearly."""

from __future__ import annotations

import math
import shutil

import pytest

from opaline.model import presets as presets_module
from opaline.model.params import RenderRequest
from opaline.model.presets import (
    PresetError,
    UnknownPreset,
    all_presets,
    get_preset,
    load_preset_file,
    presets_dir,
)
from opaline.model.request import resolve

# docs/design.md §6, written out independently of the preset files.
PAPER = {
    "cd-rom": dict(mdf="multipeak", mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1, theta2=0.2),
    "cd-rom-wide": dict(mdf="multipeak", mu_f=2.5, alpha=1.0, beta=5.0, theta1=0.1, theta2=0.2),
    "cd-rom-ashikhmin": dict(mdf="ashikhmin", theta1=0.2, theta2=0.4),
    "perturbed-cube": dict(mdf="multipeak", mu_f=2.0, alpha=1.0, beta=0.1, theta1=0.3, theta2=0.6),
    "nacre": dict(mdf="multipeak", mu_f=2.0, alpha=1.0, beta=0.1, theta1=0.3, theta2=0.6),
    "oil-slick": dict(mdf="multipeak", mu_f=10.0, alpha=20.0, beta=1.0, theta1=0.1, theta2=0.2),
    "oil-slick-soft": dict(mdf="multipeak", mu_f=3.0, alpha=2.0, beta=1.0,
                           theta1=math.pi / 6, theta2=math.pi / 3),
    # docs/design.md §5's defaults.
    "sphere": dict(mdf="multipeak", mu_f=8.5, alpha=2.0, beta=1.2, theta1=0.1, theta2=0.2),
}
CD_ROMS = ("cd-rom", "cd-rom-wide", "cd-rom-ashikhmin")

GOOD = """
description = "test scene"
tangents = "concentric"

[geometry]
kind = "annulus"
inner_radius = 0.125
outer_radius = 1.0
segments = 32

[camera]
eye = [0.0, 2.2, 1.9]
fov_deg = 38.0

[[lights]]
type = "point"
position = [-2.5, 1.5, 0.5]

[defaults]
mu_f = 8.5
"""


@pytest.fixture
def preset_dir(tmp_path, monkeypatch):
    """A private copy of presets/ that all_presets reads; its cache cleared on both sides."""
    root = tmp_path / "presets"
    shutil.copytree(presets_dir(), root)
    monkeypatch.setattr(presets_module, "presets_dir", lambda: root)
    all_presets.cache_clear()
    yield root
    all_presets.cache_clear()


def write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_every_file_loads():
    """Each .toml in presets/ validates, and its name is its file name."""
    files = sorted(presets_dir().glob("*.toml"))
    assert files
    for path in files:
        assert load_preset_file(path).name == path.stem


PHYSICAL = {"oil-film", "soap-bubble", "cd-rom-grating", "dvd-grating", "nacre-film",
            "anodised-titanium", "tempered-steel", "tempered-copper",  # films on metals: issue 23
            "bragg-mirror", "morpho",  # stacks: issue 23
            "coated-paint"}  # a film under a clear coat: issue 23


def test_preset_names_are_the_eight_of_design_and_the_physical_ones():
    """The presets are exactly the eight of docs/design.md §6, the five physical ones (issue
    14), the three films on metals, the two stacks and the coated paint (issue 23)."""
    assert set(all_presets()) == set(PAPER) | PHYSICAL
    assert len(all_presets()) == 19


@pytest.mark.parametrize("name", sorted(PAPER))
def test_material_matches_the_paper(name):
    """The preset's resolved material has the paper's figure parameters (docs/design.md §6)."""
    material = resolve(RenderRequest(preset=name)).material
    for field, value in PAPER[name].items():
        got = getattr(material, field)
        assert got == (pytest.approx(value, abs=1e-9) if isinstance(value, float) else value), field


@pytest.mark.parametrize("name", CD_ROMS)
def test_cd_roms_are_annuli_with_concentric_tangents(name):
    """Every CD-ROM is a flat annulus with a 7.5/60 hole ratio and concentric tangents."""
    preset = get_preset(name)
    assert preset.tangents == "concentric"
    assert preset.geometry.kind == "annulus"
    args = preset.geometry.args
    assert args["inner_radius"] / args["outer_radius"] == pytest.approx(7.5 / 60.0)


def test_scenes_match_design():
    """Cube and nacre carry normal maps; the sphere is a sphere; oil slicks share a wavy surface."""
    for name in ("perturbed-cube", "nacre"):
        assert get_preset(name).normal_map is not None
        assert get_preset(name).geometry.kind == "box"
    assert get_preset("sphere").geometry.kind == "sphere"
    assert get_preset("oil-slick").geometry == get_preset("oil-slick-soft").geometry
    assert get_preset("cd-rom").geometry == get_preset("cd-rom-wide").geometry
    assert get_preset("cd-rom").scene_key() != get_preset("sphere").scene_key()
    reloaded = load_preset_file(presets_dir() / "cd-rom.toml")
    assert reloaded.scene_key() == get_preset("cd-rom").scene_key()


def test_a_good_file_loads(tmp_path):
    """The template used below is itself valid (so the failures below are the edits')."""
    preset = load_preset_file(write(tmp_path, "mine.toml", GOOD))
    assert preset.name == "mine" and preset.defaults.mu_f == 8.5


@pytest.mark.parametrize(
    ("label", "edit", "field"),
    [
        ("wrong type", lambda t: t.replace("fov_deg = 38.0", 'fov_deg = "wide"'), "fov_deg"),
        ("wrong type in defaults", lambda t: t.replace("mu_f = 8.5", 'mu_f = "lots"'), "mu_f"),
        ("out of range", lambda t: t.replace("mu_f = 8.5", "mu_f = 2000.0"), "mu_f"),
        ("out of range camera", lambda t: t.replace("fov_deg = 38.0", "fov_deg = 200.0"),
         "fov_deg"),
        ("nan", lambda t: t.replace("mu_f = 8.5", "mu_f = nan"), "mu_f"),
        ("unknown field", lambda t: "zoom = 3\n" + t, "zoom"),
        ("unknown field in defaults", lambda t: t + "bogus = 1\n", "bogus"),
        ("unknown light type", lambda t: t.replace('type = "point"', 'type = "spot"'), "type"),
        ("unknown geometry argument", lambda t: t.replace("segments = 32", "thickness = 3"),
         "thickness"),
        ("unknown geometry", lambda t: t.replace('kind = "annulus"', 'kind = "torus"'), "torus"),
        ("bad geometry value", lambda t: t.replace("inner_radius = 0.125", "inner_radius = 2.0"),
         "radius"),
        ("unknown normal map argument",
         lambda t: t.replace("[camera]", '[normal_map]\nkind = "bumps"\nsed = 3\n\n[camera]'),
         "sed"),
    ],
)
def test_bad_preset_names_file_and_field(tmp_path, label, edit, field):
    """An invalid preset raises PresetError whose message names the file and the field."""
    path = write(tmp_path, "broken.toml", edit(GOOD))
    with pytest.raises(PresetError) as info:
        load_preset_file(path)
    message = str(info.value)
    assert "broken.toml" in message, label
    assert field in message, label


def test_bad_toml_names_the_file_and_line(tmp_path):
    """Unparseable TOML raises PresetError naming the file and where it broke."""
    path = write(tmp_path, "garbled.toml", GOOD + "\n[[[\n")
    with pytest.raises(PresetError) as info:
        load_preset_file(path)
    assert "garbled.toml" in str(info.value)
    assert "line" in str(info.value)


def test_missing_file_is_a_preset_error(tmp_path):
    """A file that cannot be read is a PresetError naming it."""
    with pytest.raises(PresetError, match="absent.toml"):
        load_preset_file(tmp_path / "absent.toml")


def test_all_presets_names_the_first_bad_file(preset_dir):
    """A bad file in presets/ stops loading with an error naming it (so the service won't start)."""
    (preset_dir / "zz-bad.toml").write_text(GOOD.replace("mu_f = 8.5", "mu_f = -1.0"))
    with pytest.raises(PresetError, match="zz-bad.toml"):
        all_presets()


def test_adding_a_preset_needs_no_code(preset_dir):
    """A new TOML file in presets/ becomes a preset by its file name."""
    (preset_dir / "my-disc.toml").write_text(GOOD)
    found = all_presets()
    assert "my-disc" in found and set(PAPER) <= set(found)
    assert get_preset("my-disc").defaults.mu_f == 8.5


def test_unknown_preset_lists_valid_names():
    """get_preset('nope') raises UnknownPreset whose message lists every valid name."""
    with pytest.raises(UnknownPreset) as info:
        get_preset("nope")
    assert isinstance(info.value, KeyError)
    message = str(info.value)
    assert "nope" in message
    for name in PAPER:
        assert name in message


def test_unknown_nested_field_lists_that_sections_fields(tmp_path):
    """An unknown key in [defaults] is answered with the fields [defaults] accepts."""
    path = write(tmp_path, "nested.toml", GOOD + "mu = 3.0\n")
    with pytest.raises(PresetError) as info:
        load_preset_file(path)
    message = str(info.value)
    assert "mu_f" in message
    assert "geometry" not in message.split("known fields")[-1]


def test_missing_section_message_is_short(tmp_path):
    """A preset without [[lights]] names the missing field without dumping the file."""
    path = write(tmp_path, "dark.toml", GOOD.split("[[lights]]")[0] + "[defaults]\nmu_f = 1.0\n")
    with pytest.raises(PresetError) as info:
        load_preset_file(path)
    message = str(info.value)
    assert "dark.toml" in message and "lights" in message
    assert "test scene" not in message  # the description belongs to the file, not the error
