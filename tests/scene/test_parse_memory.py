"""A mesh parse under a hard memory ceiling (RLIMIT_AS for its span): past the headroom
the file is refused as a MeshError (422), the process lives on, and the limit is put back."""

from __future__ import annotations

import resource
import sys

import numpy as np
import pytest

from opaline.scene import meshfile
from opaline.scene.parse_memory import limit_parse_memory, parse_ceiling

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS, /proc")


@pytest.fixture
def big_ply(tmp_path):
    import trimesh

    path = tmp_path / "sphere.ply"
    path.write_bytes(trimesh.creation.icosphere(subdivisions=7).export(file_type="ply"))
    return path  # 327 680 triangles, ~6 MB: its parse grows the address space ~70 MB


@pytest.fixture
def headroom():
    before = resource.getrlimit(resource.RLIMIT_AS)
    yield limit_parse_memory
    limit_parse_memory(None)
    meshfile._loaded.clear()
    assert resource.getrlimit(resource.RLIMIT_AS) == before  # put back


PARSE_IN_A_FRESH_PROCESS = """
import resource, sys
import numpy as np
from opaline.scene.meshfile import MeshError, load_mesh_file
from opaline.scene.parse_memory import PARSE_HEADROOM_BYTES, limit_parse_memory
before = resource.getrlimit(resource.RLIMIT_AS)
limit_parse_memory(16 << 20)
try:
    load_mesh_file(sys.argv[1])
    print("parsed")
except MeshError as exc:
    print(exc)
assert resource.getrlimit(resource.RLIMIT_AS) == before  # put back
np.ones(64 << 20, dtype=np.uint8)  # outside the parse, 64 MB are had again
limit_parse_memory(PARSE_HEADROOM_BYTES)  # the workers' default reads it
print(load_mesh_file(sys.argv[1], field="concentric")[1]["triangles"])
"""


def last_two_lines(script: str, path) -> list[str]:
    """The last two lines ``script`` prints, run in a fresh Python on ``path``."""
    import subprocess

    run = subprocess.run([sys.executable, "-c", script, str(path)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert len(run.stdout.splitlines()) >= 2, run.stdout
    return run.stdout.splitlines()[-2:]


def test_a_parse_past_its_headroom_is_refused_and_the_limit_put_back(big_ply):
    """In a fresh process: a long-lived one may hold freed memory the parse reuses without
    growing its address space, so the same headroom need not be reached there."""
    refused, parsed = last_two_lines(PARSE_IN_A_FRESH_PROCESS, big_ply)
    assert "needs more than 16 MB to read" in refused
    assert parsed == "327680"


def test_the_ceiling_holds_inside_and_only_inside(headroom):
    headroom(32 << 20)
    with parse_ceiling():
        with pytest.raises(MemoryError):
            np.ones(256 << 20, dtype=np.uint8)
    assert np.ones(256 << 20, dtype=np.uint8).size == 256 << 20


def test_no_headroom_no_ceiling(headroom):
    headroom(None)
    with parse_ceiling():
        assert np.ones(256 << 20, dtype=np.uint8).size == 256 << 20


REFUSE_IN_A_FRESH_PROCESS = """
import sys
from opaline.scene.meshfile import MeshError, load_mesh_file
from opaline.scene.parse_memory import PARSE_HEADROOM_BYTES, limit_parse_memory
limit_parse_memory(PARSE_HEADROOM_BYTES)
try:
    load_mesh_file(sys.argv[1])
except MeshError as exc:
    print(exc)
print("trimesh" in sys.modules, "scipy" in sys.modules)
"""


def test_a_file_the_cheap_checks_refuse_never_imports_the_parser(tmp_path):
    """The check lane's worker refuses hostile files without trimesh and scipy (~170 MB of
    it): importing them ahead of every parse grew that worker past the HTTP test's bound."""
    from hostile_meshes import glb_claiming_vertices

    path = tmp_path / "claims.glb"
    path.write_bytes(glb_claiming_vertices())
    refused, imported = last_two_lines(REFUSE_IN_A_FRESH_PROCESS, path)
    assert "limit of 6000000" in refused
    assert imported == "False False"
