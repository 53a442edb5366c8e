"""A plain ``pip install`` of the wheel gives a working ``opaline``: data, imports, commands."""

from __future__ import annotations

import ast
import os
import re
import socket
import subprocess
import sys
import time
import tomllib
import urllib.error
import urllib.request
import zipfile
from importlib.metadata import distributions, packages_distributions
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "service" / "opaline"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PROXY_VARS = ("http_proxy", "https_proxy", "all_proxy", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(out), str(ROOT)],
        check=True, capture_output=True, timeout=120,
    )
    return next(out.glob("opaline-*.whl"))


def test_wheel_contains_every_shader_and_preset(wheel):
    """The built wheel ships glsl/ as opaline/_glsl and presets/ as opaline/_presets."""
    names = set(zipfile.ZipFile(wheel).namelist())
    for source in (ROOT / "glsl").rglob("*.glsl"):
        assert f"opaline/_glsl/{source.relative_to(ROOT / 'glsl').as_posix()}" in names
    for preset in (ROOT / "presets").glob("*.toml"):
        assert f"opaline/_presets/{preset.name}" in names
    assert any(name.endswith("entry_points.txt") for name in names)
    assert "opaline/model/quality_table.json" in names  # quality=auto's measurements
    for source in (PACKAGE / "server" / "web").iterdir():  # the tuning page and its modules
        assert f"opaline/server/web/{source.name}" in names


# -- the runtime import closure --------------------------------------------------------------


def canonical(name: str) -> str:
    """A distribution name as pip compares them (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def runtime_dependencies() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    return {canonical(re.split(r"[\s<>=!~;\[]", spec, maxsplit=1)[0])
            for spec in project["dependencies"]}


def third_party_imports() -> dict[str, list[str]]:
    """Top-level module -> the package files importing it (function-level imports included)."""
    found: dict[str, list[str]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.partition(".")[0]
                if top != "opaline" and top not in sys.stdlib_module_names:
                    found.setdefault(top, []).append(str(path.relative_to(ROOT)))
    return found


def module_providers() -> dict[str, list[str]]:
    """``packages_distributions``, plus top-level extension modules (``OpenEXR.cpython-….so``),
    which it does not list on Python 3.11."""
    providers = {k: list(v) for k, v in packages_distributions().items()}
    for dist in distributions():
        for file in dist.files or []:
            if "/" not in str(file) and str(file).endswith((".so", ".pyd")):
                providers.setdefault(str(file).split(".")[0], []).append(dist.metadata["Name"])
    return providers


def test_every_third_party_import_is_a_runtime_dependency():
    """Each module the package imports comes from a distribution in [project].dependencies."""
    declared = runtime_dependencies()
    providers = module_providers()
    imports = third_party_imports()
    assert "numpy" in imports and "httpx" in imports  # the walk sees top-level and lazy imports
    missing = {}
    for module, files in sorted(imports.items()):
        dists = {canonical(d) for d in providers.get(module, [])}
        if not dists & declared:
            missing[module] = (sorted(dists) or ["<not installed>"], sorted(set(files)))
    assert not missing, f"imported but not a runtime dependency (module: dists, files): {missing}"


# -- a fresh venv, from outside the checkout -------------------------------------------------


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def wait_healthy(url: str, server: subprocess.Popen, log: Path, timeout_s: float = 90) -> None:
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        assert server.poll() is None, f"opaline serve exited:\n{log.read_text()[-3000:]}"
        try:
            with opener.open(url + "/healthz", timeout=2) as answer:
                if answer.status == 200:
                    return
        except (urllib.error.URLError, OSError):
            pass
        time.sleep(0.2)
    pytest.fail(f"opaline serve not healthy in {timeout_s:.0f} s:\n{log.read_text()[-3000:]}")


@pytest.mark.slow
def test_fresh_venv_install_runs_every_entry_point(wheel, tmp_path):
    """pip install of the wheel alone (deps from the index) imports, renders, serves, batches."""
    # Nothing of the checkout may leak in: no PYTHONPATH (pip would take service/'s
    # egg-info for an installed opaline and skip it), a cwd outside it, loopback only.
    env = {k: v for k, v in os.environ.items() if k not in PROXY_VARS + ("PYTHONPATH",)}
    env["NO_PROXY"] = env["no_proxy"] = "127.0.0.1,localhost"
    work = tmp_path / "work"
    work.mkdir()

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, env=env, timeout=120)
    bin_dir = venv / "bin"
    install = subprocess.run(
        [str(bin_dir / "python"), "-m", "pip", "install", "-q", str(wheel)],
        cwd=work, env=env, capture_output=True, text=True, timeout=180,
    )
    assert install.returncode == 0, install.stdout[-2000:] + install.stderr[-3000:]

    def run(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
        done = subprocess.run(args, cwd=work, env=env, capture_output=True, timeout=timeout)
        assert done.returncode == 0, (args, done.stdout[-2000:], done.stderr[-3000:])
        return done

    where = run(str(bin_dir / "python"), "-c",
                "import opaline; from opaline import render; print(opaline.__file__)")
    assert Path(where.stdout.decode().strip()).is_relative_to(venv)

    opaline = str(bin_dir / "opaline")
    if "--version" in run(opaline, "--help").stdout.decode():
        assert "0.2.0" in run(opaline, "--version").stdout.decode()

    small = ("--size", "64x64", "--quality", "draft")
    run(opaline, "render", "cd-rom", "-o", "out.png", *small)
    assert (work / "out.png").read_bytes().startswith(PNG_MAGIC)
    # `-o -` means standard output where the CLI supports it; an older CLI writes a
    # file named "-" instead, which is not a failure of the install.
    to_stdout = run(opaline, "render", "cd-rom", "-o", "-", *small)
    if not (work / "-").exists():
        assert to_stdout.stdout.startswith(PNG_MAGIC)

    (work / "disc.toml").write_text('preset = "cd-rom"\nmu_f = 6\nwidth = 64\nheight = 64\n'
                                    'quality = "draft"\n')
    port = free_port()
    log = tmp_path / "serve.log"
    with log.open("w") as sink:
        server = subprocess.Popen(
            [opaline, "serve", "--host", "127.0.0.1", "--port", str(port), "--workers", "1",
             "--log-level", "warning"],
            cwd=work, env=env, stdout=sink, stderr=subprocess.STDOUT)
        try:
            base = f"http://127.0.0.1:{port}"
            wait_healthy(base, server, log)
            run(opaline, "batch", "--server", base, "--out", "thumbs", "disc.toml")
        finally:
            server.terminate()
            try:
                server.wait(20)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait(5)
    thumbs = list((work / "thumbs").rglob("*.png"))
    assert [p.name for p in thumbs] == ["disc.png"], thumbs
    assert thumbs[0].read_bytes().startswith(PNG_MAGIC)


def _setup_in(tmp_path: Path, stamp: str, extras: str) -> tuple[str, str]:
    """scripts/setup.sh run in a copy of the checkout's set-up files whose .venv's python
    only records what it is asked; (its calls, the stamp after)."""
    root = Path(__file__).resolve().parents[1]
    (tmp_path / "scripts").mkdir(parents=True)
    (tmp_path / "scripts" / "setup.sh").write_bytes((root / "scripts" / "setup.sh").read_bytes())
    (tmp_path / "pyproject.toml").write_bytes((root / "pyproject.toml").read_bytes())
    python = tmp_path / ".venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text(f'#!/bin/sh\necho "$*" >> {tmp_path}/calls\n')
    python.chmod(0o755)
    (tmp_path / ".venv" / ".opaline-stamp").write_text(stamp + "\n")
    env = {**os.environ, "OPALINE_EXTRAS": extras, "OPALINE_EXTRA_DEBS": ""}
    subprocess.run(["bash", str(tmp_path / "scripts" / "setup.sh")], env=env, check=True,
                   capture_output=True)
    calls = tmp_path / "calls"
    return (calls.read_text() if calls.exists() else ""), \
        (tmp_path / ".venv" / ".opaline-stamp").read_text().strip()


def test_setup_keeps_installed_extras_and_installs_missing_ones(tmp_path):
    """scripts/serve after scripts/test found the stamp's extras ('test') unlike its own
    (none) and reinstalled, needing the network, every time the two alternated."""
    import hashlib

    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256((root / "pyproject.toml").read_bytes()).hexdigest()[:16]
    calls, stamp = _setup_in(tmp_path / "serve", f"{digest}-test", "")
    assert calls == "" and stamp == f"{digest}-test"
    calls, stamp = _setup_in(tmp_path / "test", f"{digest}-", "test")
    assert "install -q -e .[test]" in calls and stamp == f"{digest}-test"
    calls, stamp = _setup_in(tmp_path / "changed", "0123456789abcdef-test", "")
    assert "install -q -e ." in calls and stamp == f"{digest}-"
