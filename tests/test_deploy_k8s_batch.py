"""deploy/k8s/batch: the Indexed Job's shards and the merge after it, run as written.

tests/test_deploy_k8s.py validates the manifests against the Kubernetes schemas with
the others; here they must agree with the CLI (one shard per completion index, every
summary where the merge looks for it, the server the shared cache), and their very
shell commands, run on this machine for N=2 against a real service, must merge to
what one unsharded run gives.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from urllib.parse import urlsplit

import pytest
import yaml

from opaline.server.localserver import LocalServer, loopback_env
from test_deploy_nginx import REPLICA_ENV

ROOT = Path(__file__).resolve().parent.parent
BATCH = ROOT / "deploy" / "k8s" / "batch"
SMALL = 'width = 32\nheight = 32\nquality = "draft"\n'
MATERIALS = {f"m{i}.toml": f'preset = "cd-rom"\nmu_f = {1 + i / 2}\n' + SMALL for i in range(5)}
MATERIALS["sub/ball.toml"] = 'preset = "sphere"\nmu_f = 3\n' + SMALL
MATERIALS["sub/bad.toml"] = 'preset = "cd-rom"\nmu_f = 5000\n' + SMALL  # fails: out of range


def manifest(name: str) -> list[dict]:
    return [doc for doc in yaml.safe_load_all((BATCH / name).read_text()) if doc]


def job(name: str) -> dict:
    return next(d for d in manifest(name) if d["kind"] == "Job")


def pod(job: dict) -> dict:
    return job["spec"]["template"]["spec"]


def env_of(job: dict) -> dict[str, str]:
    return {e["name"]: e["value"] for e in pod(job)["containers"][0]["env"]}


def script(job: dict) -> str:
    container = pod(job)["containers"][0]
    assert container["command"] == ["sh", "-c"] and len(container["args"]) == 1
    return container["args"][0]


def test_one_shard_per_index_on_one_shared_volume():
    """completions = parallelism = SHARDS; both Jobs mount the ReadWriteMany claim where
    BATCH_DIR says; the shards ask the shared cache's Service."""
    shards, merge = job("job.yaml"), job("merge.yaml")
    spec = shards["spec"]
    assert spec["completionMode"] == "Indexed"
    assert spec["completions"] == spec["parallelism"] == int(env_of(shards)["SHARDS"])
    claim = next(d for d in manifest("job.yaml") if d["kind"] == "PersistentVolumeClaim")
    assert claim["spec"]["accessModes"] == ["ReadWriteMany"]
    for one in (shards, merge):
        mount = next(m for m in pod(one)["containers"][0]["volumeMounts"]
                     if m["mountPath"] == env_of(one)["BATCH_DIR"])
        volume = next(v for v in pod(one)["volumes"] if v["name"] == mount["name"])
        assert volume["persistentVolumeClaim"]["claimName"] == claim["metadata"]["name"]
    server = urlsplit(env_of(shards)["OPALINE_SERVER"])
    cache = next(d for d in yaml.safe_load_all((ROOT / "deploy/k8s/nginx.yaml").read_text())
                 if d and d["kind"] == "Service")
    assert (server.hostname, server.port or 80) == (cache["metadata"]["name"],
                                                   cache["spec"]["ports"][0]["port"])


def run_script(text: str, env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    """The manifest's `sh -c` script with `opaline` on PATH as the image has it."""
    bin_dir = cwd / "bin"
    bin_dir.mkdir(exist_ok=True)
    shim = bin_dir / "opaline"
    shim.write_text(f'#!/bin/sh\nexec {sys.executable} -m opaline "$@"\n')
    shim.chmod(0o755)
    full = loopback_env(**env, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    return subprocess.run(["sh", "-c", text], env=full, cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def comparable(out: Path, summary: dict) -> dict:
    """Counts, and each item but for its timing, with its output's bytes."""
    def item(record: dict) -> dict:
        output = record["output"] and Path(record["output"])
        data = output.read_bytes() if output and output.is_file() else None
        return {**record, "seconds": None, "output": output and output.relative_to(out).as_posix(),
                "bytes": data}
    return {"counts": summary["counts"],
            "items": sorted((item(r) for r in summary["items"]), key=lambda r: r["name"])}


@pytest.mark.gl
def test_the_jobs_commands_merge_to_an_unsharded_run(tmp_path):
    """Index 0 and 1 of the Job with SHARDS=2, then the merge Job, against a real service:
    the merged summary and images equal one unsharded `opaline batch --server`. A failed
    material ends its shard (exit 0, listed in its summary) and fails the merge (1)."""
    materials = tmp_path / "materials"
    for name, text in MATERIALS.items():
        (materials / name).parent.mkdir(parents=True, exist_ok=True)
        (materials / name).write_text(text)
    with LocalServer(env=REPLICA_ENV) as server:
        whole = tmp_path / "whole"
        unsharded = run_script(f'exec opaline batch "{materials}" --out "{whole}" '
                               f'--server "{server.base}"', {}, tmp_path)
        assert unsharded.returncode == 1, unsharded.stderr  # bad.toml
        env = {"SHARDS": "2", "BATCH_DIR": str(tmp_path), "OPALINE_SERVER": server.base}
        for index in (0, 1):
            done = run_script(script(job("job.yaml")),
                              {**env, "JOB_COMPLETION_INDEX": str(index)}, tmp_path)
            assert done.returncode == 0, done.stderr
    results = tmp_path / "results"
    assert sorted(p.name for p in results.glob("summary-*")) == [
        "summary-1-of-2.json", "summary-2-of-2.json"]
    merged = run_script(script(job("merge.yaml")), {"BATCH_DIR": str(tmp_path)}, tmp_path)
    assert merged.returncode == 1, merged.stderr
    assert "2 shards, 6 rendered, 0 skipped, 1 failed" in merged.stdout
    summary = json.loads((results / "summary.json").read_text())
    whole_summary = json.loads((whole / "summary.json").read_text())
    assert comparable(results, summary) == comparable(whole, whole_summary)
    assert summary["counts"] == {"rendered": 6, "skipped": 0, "failed": 1}
    assert (results / "sheet.png").is_file() and (results / "junit.xml").is_file()
