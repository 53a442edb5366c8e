"""An environment named by its path: the CLI, the Python API and local batches take a
user's .hdr/.exr wherever it is (as they take a mesh); the service takes names only."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.local.context import local_context
from opaline.model.material_file import load_material
from opaline.model.params import RenderRequest
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context, UnknownEnvironment, prepare
from opaline.scene import environments
from opaline.scene.environment_files import EnvironmentMapError

cv2 = pytest.importorskip("cv2")


def write_hdr(path, rgb: tuple[float, float, float]) -> None:
    radiance = np.broadcast_to(np.array(rgb, np.float32), (16, 32, 3))
    assert cv2.imwrite(str(path), np.ascontiguousarray(radiance[..., ::-1]))


def test_a_path_is_taken_where_asked_and_refused_where_not(tmp_path):
    write_hdr(tmp_path / "red.hdr", (1.0, 0.1, 0.1))
    path = str(tmp_path / "red.hdr")
    assert environments.check_name(path, None, paths=True) == (tmp_path / "red.hdr").resolve()
    with pytest.raises(EnvironmentMapError, match="not known"):
        environments.check_name(path, None)  # the service: names of its folder only
    with pytest.raises(EnvironmentMapError, match="not known"):
        environments.check_name(path, tmp_path)
    red = environments.resolve_map(path, None, paths=True)
    assert red.shape[-1] == 3 and red[..., 0].mean() > 5 * red[..., 1].mean()


def test_the_folder_names_first_and_a_missing_path_is_said(tmp_path, monkeypatch):
    folder, here = tmp_path / "folder", tmp_path / "here"
    folder.mkdir(), here.mkdir()
    write_hdr(folder / "room.hdr", (0.1, 0.1, 1.0))
    write_hdr(here / "room.hdr", (1.0, 0.1, 0.1))
    monkeypatch.chdir(here)
    assert environments.check_name("room.hdr", folder, paths=True) == folder / "room.hdr"
    assert environments.check_name("room.hdr", None, paths=True) == (here / "room.hdr").resolve()
    with pytest.raises(EnvironmentMapError, match="no such file"):
        environments.check_name(str(here / "gone.hdr"), folder, paths=True)
    with pytest.raises(EnvironmentMapError, match="path"):  # the message offers paths
        environments.check_name("gone.hdr", None, paths=True)


def test_local_requests_take_a_path_and_key_its_content(tmp_path):
    write_hdr(tmp_path / "map.hdr", (1.0, 0.5, 0.2))
    request = RenderRequest(preset="sphere", environment=str(tmp_path / "map.hdr"))
    first = prepare(request, local_context(None))
    write_hdr(tmp_path / "map.hdr", (0.2, 0.5, 1.0))  # replaced under its name
    assert prepare(request, local_context(None)).key != first.key
    served = Context(Limits(None), local_context(None).meshes, tmp_path)
    with pytest.raises(UnknownEnvironment):
        prepare(request, served)


def test_a_key_does_not_depend_on_where_the_command_ran(tmp_path, monkeypatch):
    """A batch run from another folder (or given the manifest's absolute path) rendered its
    environment-map items again: the key held the path as written. Meshes were keyed by
    their content already."""
    (tmp_path / "set" / "maps").mkdir(parents=True)
    write_hdr(tmp_path / "set" / "maps" / "red.hdr", (1.0, 0.1, 0.1))
    keys = set()
    for cwd, written in ((tmp_path, "set/maps/red.hdr"), (tmp_path / "set", "maps/red.hdr"),
                         (tmp_path / "set" / "maps", "red.hdr"),
                         ("/", str(tmp_path / "set" / "maps" / "red.hdr"))):
        monkeypatch.chdir(cwd)
        request = RenderRequest(preset="sphere", environment=written)
        keys.add(prepare(request, local_context(None)).key)
    assert len(keys) == 1


def test_a_material_file_names_its_environment_beside_itself(tmp_path, monkeypatch):
    (tmp_path / "maps").mkdir()
    write_hdr(tmp_path / "maps" / "room.hdr", (1.0, 1.0, 1.0))
    write_hdr(tmp_path / "beside.hdr", (1.0, 1.0, 1.0))
    material = tmp_path / "m.toml"
    monkeypatch.chdir("/")
    for written, meant in (("maps/room.hdr", tmp_path / "maps" / "room.hdr"),
                           ("beside.hdr", tmp_path / "beside.hdr"),
                           ("folder-only.hdr", "folder-only.hdr"), ("studio", "studio")):
        material.write_text(f'preset = "sphere"\nenvironment = "{written}"\n')
        assert load_material(material).environment == str(meant)
    override = load_material(material, {"environment": "beside.hdr"})
    assert override.environment == "beside.hdr"  # a command line's value is the user's own


@pytest.mark.gl
def test_the_python_api_lights_by_the_file_at_a_path(local, tmp_path):
    """The map read is the file's: a red room reddens the sphere, a blue one blues it."""
    means = {}
    for name, rgb in (("red", (2.0, 0.2, 0.2)), ("blue", (0.2, 0.2, 2.0))):
        write_hdr(tmp_path / f"{name}.hdr", rgb)
        request = RenderRequest(preset="sphere", environment=str(tmp_path / f"{name}.hdr"),
                                width=32, height=32, quality="draft")
        image = local.render_array(request)
        means[name] = image[..., :3][image[..., 3] > 0.5].mean(0)
    assert means["red"][0] > 3 * means["red"][2] and means["blue"][2] > 3 * means["blue"][0]


def test_a_link_keeps_its_own_name_and_a_users_home_that_is_none_is_a_plain_error(tmp_path):
    """A map that is a link to a content store's suffix-less blob was renamed to the blob's
    path by the key's absolute path, which then was no map ("not known"); and `~nobody/`
    raised RuntimeError past every caller (a batch's collect aborted)."""
    (tmp_path / "store").mkdir(), (tmp_path / "maps").mkdir()
    write_hdr(tmp_path / "store" / "blob.hdr", (1.0, 1.0, 1.0))
    (tmp_path / "store" / "blob.hdr").rename(tmp_path / "store" / "blob")
    (tmp_path / "maps" / "loft.hdr").symlink_to(tmp_path / "store" / "blob")
    from opaline.local.context import file_meshes

    context = Context(Limits(None), file_meshes, tmp_path / "maps", environment_paths=True)
    for written in ("loft.hdr", str(tmp_path / "maps" / "loft.hdr")):
        job = prepare(RenderRequest(preset="sphere", environment=written), context).job
        assert job.environment is not None and job.environment.endswith("loft.hdr")
        assert environments.check_name(job.environment, tmp_path / "maps", paths=True)
    with pytest.raises(EnvironmentMapError, match="no such file"):
        environments.check_name("~nosuchuser4711/x.hdr", None, paths=True)
    manifest = tmp_path / "m.manifest.toml"
    manifest.write_text('[[material]]\nname = "a"\nenvironment = "~nosuchuser4711/x.hdr"\n'
                        'mesh = "~nosuchuser4711/m.obj"\n')
    from opaline.model.materials import collect

    (item,) = collect([manifest])
    assert item.request is not None and "nosuchuser4711" in str(item.request.environment)
