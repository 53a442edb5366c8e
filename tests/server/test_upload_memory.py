"""Issue 24, item 2: uploads are streamed to disk, so 16 concurrent 100 MiB uploads grow
the HTTP process by a bounded amount (README, "Bounded memory"), not by their size.

A real ``opaline serve``: what is measured is uvicorn's own buffering as well as the
route's. Before streaming, the same run grew its peak by 3051 MiB.
"""

from __future__ import annotations

import concurrent.futures
import http.client
import re
from pathlib import Path

import pytest

from opaline.server.localserver import HOST, LocalServer, ServerError

MIB = 1024 * 1024
UPLOADS, UPLOAD_BYTES = 16, 100 * MIB
# What 16 uploads in flight may add to the HTTP process: per upload about a 64 KiB chunk
# unread in uvicorn, the chunk the route writes and a hash's state; the rest is slack for
# the interpreter's allocator. Measured: +0.4 MiB (3051 MiB before streaming).
UPLOADS_MAX_GROWTH_BYTES = 16 * MIB
CHUNK = b"\0" * MIB  # no mesh format starts so: the worker's check refuses it at once


def status_kb(pid: int, field: str) -> int:
    text = Path(f"/proc/{pid}/status").read_text()
    return int(re.search(rf"{field}:\s+(\d+) kB", text).group(1))


def upload(port: int) -> int:
    conn = http.client.HTTPConnection(HOST, port, timeout=300)
    conn.putrequest("POST", "/v1/meshes")
    conn.putheader("Content-Type", "application/octet-stream")
    conn.putheader("Content-Length", str(UPLOAD_BYTES))
    conn.endheaders()
    for _ in range(UPLOAD_BYTES // MIB):
        conn.send(CHUNK)
    status = conn.getresponse().status
    conn.close()
    return status


def test_concurrent_large_uploads_stay_out_of_memory(tmp_path, capsys):
    env = {"OPALINE_WARMUP": "false", "OPALINE_CALIBRATE": "false",
           "OPALINE_MESH_MAX_BYTES": str(128 * MIB), "OPALINE_BODY_TIMEOUT_S": "300",
           "TMPDIR": str(tmp_path)}
    try:
        server = LocalServer(workers=1, env=env).__enter__()
    except ServerError as exc:
        pytest.fail(str(exc))
    with server:
        pid = server.proc.pid
        before = status_kb(pid, "VmRSS") * 1024
        with concurrent.futures.ThreadPoolExecutor(UPLOADS) as pool:
            codes = list(pool.map(upload, [server.port] * UPLOADS))
        grown = status_kb(pid, "VmHWM") * 1024 - before
        with capsys.disabled():
            print(f"\n  upload figure: {UPLOADS} x {UPLOAD_BYTES // MIB} MiB concurrent uploads "
                  f"grew the HTTP process's peak RSS by {grown / MIB:.1f} MiB "
                  f"(from {before / MIB:.0f} MiB); answers {sorted(set(codes))}")
        assert all(code in (422, 503) for code in codes), codes  # zeros are no mesh
        assert grown <= UPLOADS_MAX_GROWTH_BYTES
        spools = [p for p in tmp_path.rglob("opaline-upload-*")]
        assert not spools, spools  # refused uploads leave no file
