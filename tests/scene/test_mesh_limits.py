"""Hostile mesh files (issue 24): each refused before trimesh allocates for it, quickly, by a
message naming the limit, with the parsing process's peak RSS bounded.

Each file is parsed in a fresh process (as a worker would), so its peak RSS is its own; an
address-space cap keeps a regression from taking the machine down with it.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import hostile_meshes as hostile
from hostile_meshes import HOSTILE

# Peak RSS of a process that imported trimesh and parsed the file: about 90 MB before any
# file (the interpreter, NumPy, trimesh). Before these checks the files below took it to
# 450 MB (textures) and past 2 GB (the 3e7-vertex accessor, at the address-space cap).
PEAK_RSS_MB = 400
SECONDS = 2.0
CAP_BYTES = 3 << 30

PARSE = """
import json, resource, sys, time
resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap}))
from opaline.scene.meshfile import MeshError, parse_mesh
data = open(sys.argv[1], "rb").read()
start = time.perf_counter()
try:
    answer = {{"summary": parse_mesh(data)[1]}}
except MeshError as exc:
    answer = {{"error": str(exc)}}
answer["seconds"] = time.perf_counter() - start
# VmHWM, not ru_maxrss: Linux carries the forking parent's maxrss across exec.
answer["peak_mb"] = next(int(line.split()[1]) for line in open("/proc/self/status")
                         if line.startswith("VmHWM:")) / 1024
print(json.dumps(answer))
"""


def parse_elsewhere(tmp_path: Path, data: bytes) -> dict:
    path = tmp_path / "upload.bin"
    path.write_bytes(data)
    code = PARSE.format(cap=CAP_BYTES)
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1])




@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_file_refused_quickly_naming_the_limit(tmp_path, capsys, name):
    build, words = HOSTILE[name]
    data = build()
    found = parse_elsewhere(tmp_path, data)
    with capsys.disabled():
        print(f"\n  {name}: {len(data)} bytes, {found['seconds']:.2f} s, "
              f"peak {found['peak_mb']:.0f} MB: {found.get('error', found.get('summary'))}")
    assert words in found.get("error", ""), found
    assert found["seconds"] < SECONDS and found["peak_mb"] < PEAK_RSS_MB


def test_textures_are_never_decoded(tmp_path, capsys):
    """Two 8000² PNGs (16 KB of GLB): the mesh and its UVs load, the images are dropped."""
    data = hostile.glb_with_textures()
    found = parse_elsewhere(tmp_path, data)
    with capsys.disabled():
        print(f"\n  two 8000² textures: {len(data)} bytes, {found['seconds']:.2f} s, "
              f"peak {found['peak_mb']:.0f} MB")
    assert found["summary"]["triangles"] == 1 and found["summary"]["uvs"], found
    assert found["seconds"] < SECONDS and found["peak_mb"] < PEAK_RSS_MB


def test_declared_sizes_are_checked_against_the_bytes():
    """An accessor past its view, a view past its buffer, a malformed count: refused by name."""
    from opaline.scene.meshfile import MeshError, parse_mesh

    header = hostile.triangle_gltf([{"mesh": 0}], [0])
    header["accessors"][0]["count"] = 4  # 48 bytes from a 36-byte view
    with pytest.raises(MeshError, match="accessor 0 needs 48 bytes of its bufferView, which has 36"):
        parse_mesh(json.dumps(header).encode())
    header["accessors"][0]["count"] = 3
    header["bufferViews"][0]["byteLength"] = 4000
    with pytest.raises(MeshError, match="bufferView 0 claims bytes 0-4000 of buffer 0, which holds 36"):
        parse_mesh(json.dumps(header).encode())
    header["bufferViews"][0]["byteLength"] = 36
    header["accessors"][0]["count"] = "3"
    with pytest.raises(MeshError, match="accessor 0's count is '3', not a count"):
        parse_mesh(json.dumps(header).encode())
    ply = hostile.ply_with_lines(0).replace(b"element face 1", b"element face 9000000")
    with pytest.raises(MeshError, match="9000000 triangles is over this service's limit of 2000000"):
        parse_mesh(ply)
    ply = hostile.ply_with_lines(0).replace(b"element vertex 3", b"element vertex 7000000")
    with pytest.raises(MeshError, match="'vertex' declares 7000000 rows, over this service's limit of 6000000"):
        parse_mesh(ply)
