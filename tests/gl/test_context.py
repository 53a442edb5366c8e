"""Headless GL contexts (opaline.gl.context, opaline.gl.osmesa): choice, fallback, agreement."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from opaline.gl import context, osmesa
from opaline.gl.context import ContextError, create_context, pick_egl_device, requested_backend
from opaline.settings import SettingsError

ROOT = Path(__file__).resolve().parents[2]
SOFTWARE = "EGL_MESA_device_software"

# Makes libOSMesa unfindable in a child process, leaving every other library alone.
HIDE_OSMESA = textwrap.dedent("""
    import ctypes, ctypes.util
    _find, _cdll = ctypes.util.find_library, ctypes.CDLL
    def find_library(name):
        return None if "osmesa" in name.lower() else _find(name)
    def CDLL(name, *args, **kwargs):
        if name and "osmesa" in str(name).lower():
            raise OSError(f"{name}: cannot open shared object file")
        return _cdll(name, *args, **kwargs)
    ctypes.util.find_library, ctypes.CDLL = find_library, CDLL
""")


def run(*args: str) -> subprocess.CompletedProcess:
    # The checkout's package (service/), not whichever opaline the venv has installed.
    environment = {**os.environ, "PYTHONPATH": str(ROOT / "service")}
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=environment,
                          capture_output=True, text=True, timeout=120)


def run_python(code: str) -> subprocess.CompletedProcess:
    return run("-c", code)


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return run("-m", "opaline.cli.main", *args)


# Choosing a backend


@pytest.mark.parametrize("name", ["egl", "osmesa", "auto", " EGL ", "OSMesa"])
def test_requested_backend_accepts_known_names(name):
    """egl, osmesa and auto are accepted, ignoring case and surrounding space."""
    assert requested_backend(name) == name.strip().lower()


@pytest.mark.parametrize("name", ["vulkan", "glx", "e gl"])
def test_requested_backend_refuses_unknown_names(name):
    """An unknown backend raises ContextError listing egl, osmesa and auto."""
    with pytest.raises(ContextError) as info:
        requested_backend(name)
    message = str(info.value)
    assert name.strip().lower() in message
    for known in ("egl", "osmesa", "auto"):
        assert known in message


def test_requested_backend_reads_the_environment(monkeypatch):
    """Without an argument OPALINE_GL_BACKEND decides; egl when it is unset; an argument wins."""
    monkeypatch.delenv("OPALINE_GL_BACKEND", raising=False)
    assert requested_backend() == "egl"
    monkeypatch.setenv("OPALINE_GL_BACKEND", "osmesa")
    assert requested_backend() == "osmesa"
    assert requested_backend(None) == "osmesa"
    assert requested_backend("egl") == "egl"
    monkeypatch.setenv("OPALINE_GL_BACKEND", "Auto")
    assert requested_backend() == "auto"
    # A bad variable is a settings error naming it (one line, exit 2 from the command).
    monkeypatch.setenv("OPALINE_GL_BACKEND", "bogus")
    with pytest.raises(SettingsError, match="OPALINE_GL_BACKEND='bogus': choose one of egl"):
        requested_backend()
    with pytest.raises(ContextError, match="backend='bogus2' is not known"):
        requested_backend("bogus2")


def test_create_context_refuses_unknown_backend_first(monkeypatch):
    """create_context validates the name before trying any backend."""
    tried = []
    monkeypatch.setattr(context, "create_egl", lambda: tried.append("egl"))
    monkeypatch.setattr(context, "create_osmesa", lambda: tried.append("osmesa"))
    with pytest.raises(ContextError, match="egl, osmesa, auto"):
        create_context("directx")
    assert tried == []


# Picking an EGL device


@pytest.mark.parametrize(
    ("devices", "expected"),
    [
        ([], 0),
        ([f"{SOFTWARE}"], 0),
        ([f"EGL_EXT_device_drm {SOFTWARE}", "EGL_EXT_device_drm EGL_NV_device_cuda"], 1),
        (["EGL_NV_device_cuda", f"{SOFTWARE}"], 0),
        ([f"{SOFTWARE}", f"EGL_EXT_device_base {SOFTWARE}", "EGL_EXT_device_drm"], 2),
        ([f"{SOFTWARE}", f"{SOFTWARE} EGL_EXT_device_drm"], 0),
        ([f"{SOFTWARE}_other"], 0),
        ([f"{SOFTWARE}", ""], 1),
    ],
)
def test_pick_egl_device_prefers_hardware(devices, expected):
    """The first device without EGL_MESA_device_software wins; all software (or none) gives 0."""
    assert pick_egl_device(devices) == expected


# OSMesa missing (Mesa >= 25.1)


@pytest.fixture
def no_osmesa(monkeypatch):
    """ctypes cannot find or open any library while the test runs (OSMesa is only looked up)."""

    def cannot_load(name, *args, **kwargs):
        raise OSError(f"{name}: cannot open shared object file: No such file or directory")

    monkeypatch.setattr(osmesa.ctypes.util, "find_library", lambda name: None)
    monkeypatch.setattr(osmesa.ctypes, "CDLL", cannot_load)


def test_osmesa_missing_explains_itself(no_osmesa):
    """Without libOSMesa, create_context('osmesa') names Mesa 25.1 and the egl alternative."""
    with pytest.raises(ContextError) as info:
        create_context("osmesa")
    message = str(info.value)
    assert "25.1" in message
    assert "egl" in message.lower()
    assert "OSMesa" in message


def test_osmesa_loader_raises_its_own_error(no_osmesa):
    """The loader itself reports OSMesaUnavailable (not a bare OSError) when the library is gone."""
    with pytest.raises(osmesa.OSMesaUnavailable, match="25.1"):
        osmesa.OSMesaLoader()


def test_auto_reports_every_failure(no_osmesa, monkeypatch):
    """When no backend works, 'auto' raises one ContextError carrying each backend's reason."""

    def broken_egl():
        raise ContextError("EGL context could not be created: no display")

    monkeypatch.setattr(context, "create_egl", broken_egl)
    with pytest.raises(ContextError) as info:
        create_context("auto")
    message = str(info.value)
    assert "no display" in message and "25.1" in message


@pytest.mark.gl
def test_auto_uses_egl_when_osmesa_is_missing():
    """create_context('auto') still succeeds, through EGL, on a system without libOSMesa."""
    code = HIDE_OSMESA + textwrap.dedent("""
        from opaline.gl.context import create_context, create_osmesa, ContextError
        try:
            create_osmesa()
        except ContextError as exc:
            print("osmesa refused:", "25.1" in str(exc))
        gl = create_context("auto")
        print("backend:", gl.backend)
        print("renderer:", gl.renderer)
        gl.release()
    """)
    result = run_python(code)
    assert result.returncode == 0, result.stderr
    assert "osmesa refused: True" in result.stdout
    assert "backend: egl" in result.stdout


@pytest.mark.gl
def test_auto_falls_back_to_osmesa_when_egl_fails():
    """create_context('auto') falls back to OSMesa when EGL cannot make a context."""
    code = textwrap.dedent("""
        from opaline.gl import context
        def broken():
            raise context.ContextError("EGL context could not be created: test")
        context.create_egl = broken
        gl = context.create_context("auto")
        print("backend:", gl.backend)
        gl.release()
    """)
    result = run_python(code)
    assert result.returncode == 0, result.stderr
    assert "backend: osmesa" in result.stdout


# Both backends, same pictures


@pytest.mark.gl
def test_backends_render_the_same_image(tmp_path):
    """cd-rom rendered to .npy on EGL and on OSMesa agrees within 1e-3 of the peak."""
    images = {}
    for backend in ("egl", "osmesa"):
        out = tmp_path / f"{backend}.npy"
        result = run_cli("render", "cd-rom", "--size", "64x64", "--format", "npy",
                         "--backend", backend, "-o", str(out))
        assert result.returncode == 0, result.stderr
        images[backend] = np.load(out)
    a, b = images["egl"], images["osmesa"]
    assert a.shape == b.shape == (64, 64, 4) and a.dtype == np.float32
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))
    peak = float(np.abs(a).max())
    assert peak > 0.0
    assert float(np.abs(a - b).max()) <= 1e-3 * peak


@pytest.mark.gl
@pytest.mark.parametrize("backend", ["osmesa", "egl"])
def test_info_reports_backend_and_renderer(backend):
    """`opaline info --backend X` prints the backend it got and the GL renderer."""
    result = run_cli("info", "--backend", backend)
    assert result.returncode == 0, result.stderr
    lines = dict(line.split(": ", 1) for line in result.stdout.strip().splitlines())
    assert lines["backend"] == backend
    assert lines["renderer"].strip()
    major, minor = lines["version"].split()[0].split(".")[:2]
    assert (int(major), int(minor)) >= (3, 3)


@pytest.mark.gl
def test_context_describes_itself(backend):
    """A context in this process reports its backend, renderer and a GL >= 3.3 core version."""
    result = run_python(textwrap.dedent(f"""
        from opaline.gl.context import create_context
        gl = create_context({backend!r})
        print(sorted(gl.describe()), gl.backend, gl.ctx.version_code)
        gl.release()
    """))
    assert result.returncode == 0, result.stderr
    keys, name, version = result.stdout.rsplit(" ", 2)
    assert "'renderer'" in keys and "'backend'" in keys
    assert name == backend and int(version) >= 330


TWO_RENDERERS = textwrap.dedent("""
    import sys
    import numpy as np
    from opaline.model.params import RenderRequest
    from opaline.local.pipeline import LocalRenderer
    request = RenderRequest(preset="cd-rom", width=32, height=32, quality="draft", mu_f=3.0)
    first = LocalRenderer(sys.argv[1])
    before = first.render_array(request)
    second = LocalRenderer(sys.argv[1])
    second.render_array(request)
    second.close()
    after = first.render_array(request)
    print("max diff:", float(np.abs(after - before).max()))
    first.close()
""")


@pytest.mark.gl
@pytest.mark.parametrize("name", ["egl", "osmesa"])
def test_second_renderer_on_a_thread_leaves_the_first_intact(name):
    """Making and releasing a second renderer on the thread leaves the first one's images alone."""
    result = run("-c", TWO_RENDERERS, name)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "max diff: 0.0" in result.stdout


def test_failed_osmesa_context_is_unbound_and_destroyed(monkeypatch):
    """If moderngl cannot wrap the new OSMesa context, that context is unbound, then destroyed."""
    calls = []

    class Loader:
        def __exit__(self, *exc):
            calls.append("unbind")

        def release(self):
            calls.append("destroy")

    def broken(loader):
        raise RuntimeError("no GL functions")

    monkeypatch.setattr(context, "OSMesaLoader", Loader)
    monkeypatch.setattr(context, "_loader_context", broken)
    with pytest.raises(RuntimeError, match="no GL functions"):
        context.create_osmesa()
    assert calls == ["unbind", "destroy"]
