"""Material files and manifests parse into the request model, with errors that name the file."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from opaline.cli.main import main
from opaline.model import materials
from opaline.model.manifest_lines import entry_lines
from opaline.model.materials import MaterialError, collect, load_material, material_schema

ROOT = Path(__file__).resolve().parents[2]


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_toml_material_parses_into_the_request_model(tmp_path):
    """Every field of a TOML material file arrives in the RenderRequest, tuples included."""
    path = write(tmp_path / "disc.toml", 'preset = "cd-rom"\nmu_f = 6\nwidth = 64\n'
                 'albedo = [0.1, 0.2, 0.3]\nquality = "draft"\n')
    request = load_material(path)
    assert request.preset == "cd-rom" and request.mu_f == 6.0 and request.width == 64
    assert request.albedo == (0.1, 0.2, 0.3) and request.quality == "draft"
    assert request.height is None, "unset fields stay unset (the preset decides)"


def test_json_material_may_name_its_schema(tmp_path):
    """A JSON material file parses the same, and its "$schema" key is ignored."""
    path = write(tmp_path / "ball.json", json.dumps(
        {"$schema": "../docs/material.schema.json", "preset": "sphere", "alpha": 3}))
    request = load_material(path)
    assert request.preset == "sphere" and request.alpha == 3.0


def test_out_of_range_value_names_file_field_value_and_range(tmp_path):
    """An out-of-range field is rejected, never clamped, and the message says where and why."""
    path = write(tmp_path / "hot.toml", 'preset = "cd-rom"\nmu_f = 5000\ntheta1 = 7\n')
    with pytest.raises(MaterialError) as info:
        load_material(path)
    message = str(info.value)
    assert message.startswith(str(path))
    assert "mu_f=5000" in message and "[0 … 1000]" in message
    assert "theta1=7" in message and "2π" in message


def test_unknown_field_is_rejected_with_the_known_ones(tmp_path):
    """A misspelt field is an error that suggests the nearest field and lists the real ones."""
    path = write(tmp_path / "typo.toml", "muf = 3\n")
    with pytest.raises(MaterialError, match=r"muf: unknown field, did you mean mu_f\? "
                                            r"\(known fields: .*mu_f"):
        load_material(path)


def test_unknown_field_far_from_any_gets_no_suggestion(tmp_path):
    """No "did you mean" when nothing is close: a wrong guess would mislead."""
    path = write(tmp_path / "odd.toml", "zoom = 3\n")
    with pytest.raises(MaterialError) as info:
        load_material(path)
    assert "zoom: unknown field (known fields:" in str(info.value)


@pytest.mark.parametrize("name, text, line", [
    ("hot.toml", '# a hot disc\npreset = "cd-rom"\n\nmu_f = 5000\n', 4),
    ("hot.json", '{\n  "preset": "cd-rom",\n  "mu_f": 5000\n}\n', 3),
    ("typo.toml", 'preset = "cd-rom"\nmuf = 3\n', 2),
])
def test_validation_error_names_the_line_of_its_key(tmp_path, name, text, line):
    """A bad value is reported at file:line of its key, for editors and CI annotations."""
    path = write(tmp_path / name, text)
    with pytest.raises(MaterialError) as info:
        load_material(path)
    assert str(info.value).startswith(f"{path}:{line}: ")
    assert info.value.line == line and info.value.path == str(path)


def test_override_error_has_no_line_in_the_file(tmp_path):
    """A bad value from the command line is not pinned on a line of the file."""
    path = write(tmp_path / "disc.toml", 'preset = "cd-rom"\nmu_f = 3\n')
    with pytest.raises(MaterialError) as info:
        load_material(path, {"mu_f": 5000})
    assert info.value.line is None and str(info.value).startswith(f"{path}: mu_f=5000")


@pytest.mark.parametrize("name, text", [("empty.toml", ""), ("blank.toml", "# nothing\n"),
                                        ("empty.json", "{}"),
                                        ("schema-only.json", '{"$schema": "x.json"}')])
def test_empty_material_file_is_an_error_not_the_default_sphere(tmp_path, name, text):
    """An empty material file fails instead of silently rendering the default preset."""
    path = write(tmp_path / name, text)
    with pytest.raises(MaterialError, match="empty material file"):
        load_material(path)
    (item,) = collect([path])
    assert item.request is None and "empty material file" in item.error


@pytest.mark.parametrize("name, text, kind", [("x.toml", 'preset = "cd-rom"\nmu_f = = 3', "TOML"),
                                              ("x.json", '{"preset": "cd-rom",\nmu_f: 3', "JSON")])
def test_syntax_error_names_the_file_line_and_format(tmp_path, name, text, kind):
    """A file that is not valid TOML/JSON fails with its name, line and the parser's message."""
    path = write(tmp_path / name, text)
    with pytest.raises(MaterialError, match=rf"{re.escape(str(path))}:2: invalid {kind}"):
        load_material(path)


def test_non_table_json_is_rejected(tmp_path):
    """A JSON list is not a material."""
    path = write(tmp_path / "list.json", "[1, 2]")
    with pytest.raises(MaterialError, match="expected a table"):
        load_material(path)


def test_folder_is_collected_recursively_sorted_with_relative_names(tmp_path):
    """Folder inputs give every *.toml/*.json below them, sorted, named by relative path."""
    write(tmp_path / "m/b.toml", "mu_f = 2\n")
    write(tmp_path / "m/a.json", '{"mu_f": 1}')
    write(tmp_path / "m/sub/c.toml", "mu_f = 3\n")
    write(tmp_path / "m/.hidden.toml", "mu_f = 4\n")
    write(tmp_path / "m/notes.txt", "not a material")
    write(tmp_path / "m/out/old.png.json", '{"key": "x"}')
    items = collect([tmp_path / "m"], exclude=[tmp_path / "m/out"])
    assert [i.name for i in items] == ["a", "b", "sub/c"]
    assert [i.request.mu_f for i in items] == [1.0, 2.0, 3.0]


def test_duplicate_output_names_fail_the_second(tmp_path):
    """Two inputs that would write the same image: the second fails and says who has the name."""
    write(tmp_path / "m/disc.toml", "mu_f = 2\n")
    write(tmp_path / "m/disc.json", '{"mu_f": 3}')
    first, second = collect([tmp_path / "m"])
    assert first.error is None and first.source.endswith("disc.json")
    assert second.request is None and "already used by" in second.error


def test_missing_input_is_an_item_error_not_an_exception(tmp_path):
    """A path that does not exist becomes a failed item, so the others still render."""
    write(tmp_path / "ok.toml", "mu_f = 2\n")
    missing, ok = collect([tmp_path / "nope.toml", tmp_path / "ok.toml"])
    assert "no such file" in missing.error and ok.error is None


def test_manifest_merges_defaults_file_entry_and_overrides_in_that_order(tmp_path):
    """Manifest defaults < the referenced file < the entry's fields < command-line overrides."""
    write(tmp_path / "disc.toml", 'preset = "cd-rom"\nmu_f = 6\nwidth = 100\nheight = 100\n')
    manifest = write(tmp_path / "set.manifest.toml", """
[defaults]
width = 64
height = 64
quality = "draft"
alpha = 9

[[material]]
name = "inline"
preset = "oil-slick"
mu_f = 4

[[material]]
path = "disc.toml"
name = "disc-wide"
width = 96

[[material]]
path = "disc.toml"
""")
    items = collect([manifest], overrides={"quality": "standard"})
    assert [i.name for i in items] == ["inline", "disc-wide", "disc"]
    inline, wide, disc = (i.request for i in items)
    assert (inline.preset, inline.mu_f, inline.width, inline.alpha) == ("oil-slick", 4.0, 64, 9.0)
    assert (wide.preset, wide.mu_f, wide.width, wide.height) == ("cd-rom", 6.0, 96, 100)
    assert disc.width == 100 and all(r.quality == "standard" for r in (inline, wide, disc))


def test_manifest_entries_fail_one_by_one(tmp_path):
    """A bad entry fails alone, with the manifest, the line its entry starts on, the entry
    name and the reason (one object a line below the array's opening line)."""
    entries = [{"name": "good", "mu_f": 1}, {"name": "hot", "mu_f": -1},
               {"name": "../escape", "mu_f": 1}, {"mu_f": 1},
               {"name": "lost", "path": "missing.toml"}]
    text = '{"defaults": {"width": 64, "environment": "[{\\" ]"},\n "material": [\n' + ",\n".join(
        json.dumps(entry) for entry in entries) + "\n]}\n"
    manifest = write(tmp_path / "set.manifest.json", text)
    good, hot, escape, unnamed, lost = collect([manifest])
    assert good.error is None
    assert f"{manifest}:4: [hot]: mu_f=-1 is out of range" in hot.error and hot.line == 4
    assert "must be letters" in escape.error and escape.request is None and escape.line == 5
    assert "name=None" in unnamed.error and unnamed.line == 6
    assert "no such material file" in lost.error and lost.line == 7
    flat = write(tmp_path / "flat.manifest.json", json.dumps({"material": entries[:2]}))
    assert [item.line for item in collect([flat])] == [None, 1]


def test_manifest_toml_errors_name_the_entry_line(tmp_path):
    manifest = write(tmp_path / "set.manifest.toml",
                     '[defaults]\nwidth = 64\n\n[[material]]\nname = "a"\nmu_f = 1\n\n'
                     '[[material]]\nname = "b"\nmu_f = -2\n')
    a, b = collect([manifest])
    assert a.error is None and b.line == 8
    assert b.error.startswith(f"{manifest}:8: [b]: mu_f=-2 is out of range")


def test_manifest_lines_in_every_form_an_entry_takes(tmp_path):
    """An inline TOML array of tables, a JSON entry that is no object, and an entry whose
    material file is missing: each error starts FILE:LINE: at its entry (a review found
    them without lines, as `file[b]:`)."""
    inline = write(tmp_path / "i.manifest.toml",
                   'defaults = {width = 64}\nmaterial = [\n  {name = "a", preset = "cd-rom"},'
                   '  # a comment, "quoted" [and bracketed]\n  {name = "b", mu_f = -2},\n]\n')
    a, b = collect([inline])
    assert a.error is None and b.line == 4 and b.error.startswith(f"{inline}:4: [b]: mu_f=-2")
    mixed = write(tmp_path / "m.manifest.json",
                  '{\n "material": [\n  {"name": "a"},\n  42,\n  {"name": "c", "mu_f": -1}\n ]}\n')
    a, number, c = collect([mixed])
    assert (a.error, number.line, c.line) == (None, 4, 5)
    assert number.error == f"{mixed}:4: [material 2]: expected an object, got 42"
    missing = write(tmp_path / "p.manifest.toml",
                    '[[material]]\nname = "ok"\n\n[[material]]\npath = "sub/missing.toml"\n')
    ok, lost = collect([missing])
    assert (lost.file, lost.line) == (str(missing), 4) and "no such material file" in lost.error


@settings(max_examples=150, deadline=None)
@given(st.lists(st.dictionaries(st.sampled_from(["name", "note", "x"]),
                                st.text(alphabet='[]{},"\\#\' a\n', max_size=6)),
                min_size=1, max_size=5), st.integers(0, 3))
def test_json_entry_lines_survive_strings_that_look_like_structure(entries, indent):
    """Brackets, braces, commas and escaped quotes inside strings do not move an entry's
    line; one entry a line where the JSON is written so."""
    text = json.dumps({"defaults": {"note": "[{"}, "material": entries}, indent=indent or None)
    lines = entry_lines(text, is_json=True)
    assert len(lines) == len(entries)
    if indent:
        rows = text.splitlines()
        assert all(rows[line - 1].strip().startswith("{") for line in lines)


def test_manifest_files_are_relative_to_who_wrote_them(tmp_path, monkeypatch):
    """A mesh or environment map written in a manifest is relative to the manifest; one
    written in a material file it names, relative to that file (as when it is rendered
    alone), wherever the batch runs."""
    write(tmp_path / "meshes/m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    write(tmp_path / "sub/maps/room.hdr", "")
    write(tmp_path / "sub/disc.toml", 'preset = "cd-rom"\nenvironment = "maps/room.hdr"\n')
    manifest = write(tmp_path / "set.manifest.toml",
                     '[defaults]\nmesh = "meshes/m.obj"\n\n[[material]]\nname = "a"\n\n'
                     '[[material]]\npath = "sub/disc.toml"\n')
    monkeypatch.chdir("/")
    a, disc = collect([manifest])
    assert a.request.mesh == disc.request.mesh == str(tmp_path / "meshes/m.obj")
    assert disc.request.environment == str(tmp_path / "sub/maps/room.hdr")
    assert a.request.environment is None


def test_manifest_with_unknown_top_level_key_fails_as_a_whole(tmp_path):
    """A manifest's own structure is checked: unknown keys and an empty list are errors."""
    bad = write(tmp_path / "a.manifest.toml", '[[materials]]\nname = "x"\n')
    empty = write(tmp_path / "b.manifest.toml", "[defaults]\nwidth = 64\n")
    (item_a,), (item_b,) = collect([bad]), collect([empty])
    assert "unknown key(s) materials" in item_a.error
    assert "non-empty list" in item_b.error


def test_manifest_in_a_folder_prefixes_its_subfolder(tmp_path):
    """A manifest found inside a folder input names its entries relative to that folder."""
    write(tmp_path / "m/set/x.manifest.toml", '[[material]]\nname = "e"\nmu_f = 1\n')
    (item,) = collect([tmp_path / "m"])
    assert item.name == "set/e" and item.error is None


def test_schema_command_prints_the_file_format_and_docs_copy_is_current(capsys):
    """`opaline schema` prints the request schema, titled; docs/material.schema.json is a copy."""
    assert main(["schema"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == material_schema()
    assert printed["title"] == "Opaline material file" and printed["additionalProperties"] is False
    assert printed["properties"]["mu_f"]["anyOf"][0]["maximum"] == 1000
    assert "$schema" in printed["properties"]
    docs = json.loads((ROOT / "docs/material.schema.json").read_text())
    assert docs == printed, "regenerate with: opaline schema -o docs/material.schema.json"


def test_schema_command_writes_a_file(tmp_path):
    """`opaline schema -o FILE` writes the same JSON to FILE."""
    target = tmp_path / "s.json"
    assert main(["schema", "-o", str(target)]) == 0
    assert json.loads(target.read_text()) == material_schema()


def doc_examples() -> list[tuple[str, str]]:
    """Code blocks in docs/materials.md that start with a `# file: NAME` (or JSON "//") line."""
    text = (ROOT / "docs/materials.md").read_text()
    blocks = re.findall(r"```(?:toml|json)\n(.*?)```", text, flags=re.S)
    found = []
    for block in blocks:
        first, _, body = block.partition("\n")
        match = re.match(r"(?:#|//) file: (\S+)", first)
        if match:
            found.append((match.group(1), body))
    return found


def test_every_example_in_the_docs_is_valid(tmp_path):
    """The material files and manifests shown in docs/materials.md all parse without error."""
    examples = doc_examples()
    assert len(examples) >= 4
    for name, body in examples:
        write(tmp_path / "docs" / name, body)
    items = collect([tmp_path / "docs"])
    assert items and all(i.error is None for i in items), [i.error for i in items if i.error]
    assert any(materials.is_manifest(Path(name)) for name, _ in examples)
