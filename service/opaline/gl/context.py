"""Headless GL contexts: EGL (default), OSMesa (fallback) or the first that works.

The choice comes from ``OPALINE_GL_BACKEND`` (``egl``, ``osmesa``, ``auto``) or
an explicit argument. A context is current on the thread that made it; the
renderer that owns it must stay on that thread.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
from collections import deque
from dataclasses import dataclass, field
from functools import cache

import moderngl

from opaline.gl.osmesa import OSMesaLoader, OSMesaUnavailable
from opaline.settings import BACKENDS, BackendName, SettingsError  # noqa: F401 (re-exported)

GL_REQUIRE = 330

EGL_EXTENSIONS = 0x3055
SOFTWARE_DEVICE_EXT = "EGL_MESA_device_software"
# ctypes.util.find_library runs `ldconfig -p` in a subprocess, about 5 ms a call, and
# glcontext asks it for GL and EGL on every context unless it is given the names:
# a cold `opaline render` paid 15 ms for three calls. The usual sonames go first.
SONAMES = {"EGL": "libEGL.so.1", "GL": "libGL.so.1"}


class ContextError(RuntimeError):
    """No headless GL context could be made with the requested backend."""


@dataclass
class GLContext:
    """A moderngl context with what it turned out to be."""

    ctx: moderngl.Context
    backend: str
    renderer: str
    vendor: str
    version: str
    _loader: OSMesaLoader | None = field(default=None, repr=False)

    @property
    def has_fp64(self) -> bool:
        return "GL_ARB_gpu_shader_fp64" in self.ctx.extensions or self.ctx.version_code >= 400

    def describe(self) -> dict[str, str]:
        return {
            "backend": self.backend,
            "renderer": self.renderer,
            "vendor": self.vendor,
            "version": self.version,
        }

    def make_current(self) -> None:
        """Bind this context to the calling thread. Several contexts may share a thread
        (tests, a CLI that opens two), so every entry point binds its own first."""
        # moderngl's stubs leave Context.__enter__ and __exit__ unannotated.
        self.ctx.__enter__()  # type: ignore[no-untyped-call]

    def release(self) -> None:
        # Unbind first: a context that is still current is only destroyed later,
        # and would stay bound under whatever context the thread uses next.
        self.ctx.__exit__(None, None, None)  # type: ignore[no-untyped-call]
        self.ctx.release()
        if self._loader is not None:
            self._loader.release()
            self._loader = None


def requested_backend(explicit: str | None = None) -> str:
    name = (explicit or os.environ.get("OPALINE_GL_BACKEND") or "egl").strip().lower()
    if name not in BACKENDS:
        choices = ", ".join(BACKENDS)
        if not explicit:  # the variable's fault: said as every other bad OPALINE_* is
            raise SettingsError(f"OPALINE_GL_BACKEND={os.environ['OPALINE_GL_BACKEND']!r}: "
                                f"choose one of {choices}")
        raise ContextError(f"backend={name!r} is not known: choose one of {choices}")
    return name


@cache
def library(name: str) -> str | None:
    """The file to dlopen for libNAME: its usual soname when that loads (it is then what
    ``find_library`` names too), else what ``ctypes.util.find_library`` finds."""
    soname = SONAMES.get(name)
    if soname:
        try:
            ctypes.CDLL(soname)
            return soname
        except OSError:
            pass
    return ctypes.util.find_library(name)


def egl_device_extensions() -> list[str]:
    """Extension strings of every EGL device, in the order glcontext indexes them."""
    libname = library("EGL")
    if not libname:
        return []
    egl = ctypes.CDLL(libname)
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    query_ptr = egl.eglGetProcAddress(b"eglQueryDevicesEXT")
    string_ptr = egl.eglGetProcAddress(b"eglQueryDeviceStringEXT")
    if not query_ptr or not string_ptr:
        return []
    query = ctypes.CFUNCTYPE(
        ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p), ctypes.POINTER(ctypes.c_int)
    )(query_ptr)
    describe = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int)(string_ptr)
    devices = (ctypes.c_void_p * 16)()
    count = ctypes.c_int(0)
    if not query(16, devices, ctypes.byref(count)):
        return []
    return [(describe(devices[i], EGL_EXTENSIONS) or b"").decode() for i in range(count.value)]


def pick_egl_device(extensions: list[str]) -> int:
    """Prefer a hardware device; Mesa's software device is listed beside a GPU."""
    for index, ext in enumerate(extensions):
        if SOFTWARE_DEVICE_EXT not in ext.split():
            return index
    return 0


def _wrap(ctx: moderngl.Context, backend: str, loader: OSMesaLoader | None = None) -> GLContext:
    info = ctx.info
    return GLContext(
        ctx=ctx,
        backend=backend,
        renderer=str(info["GL_RENDERER"]),
        vendor=str(info["GL_VENDOR"]),
        version=str(info["GL_VERSION"]),
        _loader=loader,
    )


def create_egl() -> GLContext:
    override = os.environ.get("GLCONTEXT_DEVICE_INDEX")
    index = int(override) if override else pick_egl_device(egl_device_extensions())
    # GLCONTEXT_LINUX_LIBEGL / _LIBGL still win: glcontext reads them over these names.
    names = {key: found for key, found in (("libegl", library("EGL")), ("libgl", library("GL")))
             if found}
    try:
        # The stubs type each of **settings as a dict; glcontext takes plain values.
        ctx = moderngl.create_context(
            standalone=True, backend="egl", require=GL_REQUIRE, device_index=index, **names  # type: ignore[arg-type]
        )
    except Exception as exc:  # glcontext raises plain Exception subclasses
        raise ContextError(f"EGL context could not be created: {exc}") from exc
    return _wrap(ctx, "egl")


def create_osmesa() -> GLContext:
    try:
        loader = OSMesaLoader()
    except OSMesaUnavailable as exc:
        raise ContextError(f"OSMesa backend unavailable: {exc}") from exc
    try:
        ctx = _loader_context(loader)
        if ctx.version_code < GL_REQUIRE:
            raise ContextError(f"OSMesa gave GL {ctx.version_code}, Opaline needs {GL_REQUIRE}")
        return _wrap(ctx, "osmesa", loader)
    except BaseException:
        # The loader made its context current: unbind it before destroying it (as release does).
        loader.__exit__()
        loader.release()
        raise


def _loader_context(loader: OSMesaLoader) -> moderngl.Context:
    """What moderngl.create_context does, with a custom loader in place of a glcontext backend."""
    # The C extension takes a custom loader object; the stubs declare neither it nor the
    # private fields create_context sets, which are set here the same way.
    from moderngl import mgl  # type: ignore[attr-defined]

    ctx = moderngl.Context.__new__(moderngl.Context)
    ctx.mglo, ctx.version_code = mgl.create_context(context=loader)
    ctx._info = None  # type: ignore[attr-defined]
    ctx._extensions = None  # type: ignore[attr-defined]
    ctx.extra = None
    ctx._gc_mode = None  # type: ignore[attr-defined]
    ctx._objects = deque()  # type: ignore[attr-defined]
    ctx._screen = ctx.detect_framebuffer(0)  # type: ignore[attr-defined]
    ctx.fbo = ctx.detect_framebuffer()
    ctx.mglo.fbo = ctx.fbo.mglo
    return ctx


def create_context(backend: str | None = None) -> GLContext:
    """Make a headless context on the current thread."""
    name = requested_backend(backend)
    if name == "egl":
        return create_egl()
    if name == "osmesa":
        return create_osmesa()
    errors = []
    for factory in (create_egl, create_osmesa):
        try:
            return factory()
        except ContextError as exc:
            errors.append(str(exc))
    raise ContextError("no headless GL backend works: " + "; ".join(errors))
