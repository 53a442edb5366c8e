"""OSMesa as a moderngl loader: Mesa's off-screen GL, reached through ctypes.

moderngl accepts any object with ``load_opengl_function(name) -> int`` and
``release()``; this module provides one backed by libOSMesa. OSMesa contexts
are current per thread, so the loader must be created, used and released on
the one thread that owns the renderer.
"""

from __future__ import annotations

import ctypes
import ctypes.util

# Constants from GL/osmesa.h.
OSMESA_FORMAT = 0x22
OSMESA_DEPTH_BITS = 0x30
OSMESA_STENCIL_BITS = 0x31
OSMESA_PROFILE = 0x33
OSMESA_CORE_PROFILE = 0x34
OSMESA_CONTEXT_MAJOR_VERSION = 0x36
OSMESA_CONTEXT_MINOR_VERSION = 0x37
GL_RGBA = 0x1908
GL_UNSIGNED_BYTE = 0x1401

REMOVED_HINT = (
    "libOSMesa was not found. Mesa removed OSMesa in release 25.1, so newer distributions "
    "no longer ship it; on Debian 12 install the 'libosmesa6' package, or use the 'egl' "
    "backend (OPALINE_GL_BACKEND=egl), which is Mesa's long-term headless path."
)


class OSMesaUnavailable(RuntimeError):
    """libOSMesa is missing or refused to make a context."""


def _load_library() -> ctypes.CDLL:
    name = ctypes.util.find_library("OSMesa")
    for candidate in filter(None, (name, "libOSMesa.so.8", "libOSMesa.so")):
        try:
            return ctypes.CDLL(candidate)
        except OSError:
            continue
    raise OSMesaUnavailable(REMOVED_HINT)


class OSMesaLoader:
    """A current OSMesa core-profile context, exposed the way moderngl expects."""

    def __init__(self, major: int = 3, minor: int = 3) -> None:
        lib = _load_library()
        lib.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
        lib.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int), ctypes.c_void_p]
        lib.OSMesaMakeCurrent.restype = ctypes.c_ubyte
        lib.OSMesaMakeCurrent.argtypes = [
            ctypes.c_void_p,
            ctypes.c_void_p,
            ctypes.c_uint,
            ctypes.c_int,
            ctypes.c_int,
        ]
        lib.OSMesaGetProcAddress.restype = ctypes.c_void_p
        lib.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
        lib.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]
        self._lib = lib

        attribs = [
            OSMESA_FORMAT,
            GL_RGBA,
            OSMESA_DEPTH_BITS,
            24,
            OSMESA_STENCIL_BITS,
            0,
            OSMESA_PROFILE,
            OSMESA_CORE_PROFILE,
            OSMESA_CONTEXT_MAJOR_VERSION,
            major,
            OSMESA_CONTEXT_MINOR_VERSION,
            minor,
            0,
        ]
        self._ctx = lib.OSMesaCreateContextAttribs((ctypes.c_int * len(attribs))(*attribs), None)
        if not self._ctx:
            raise OSMesaUnavailable(f"OSMesa could not create a GL {major}.{minor} core context")
        # All rendering goes to framebuffer objects; the window-system buffer only
        # has to exist for MakeCurrent, so a single pixel is enough.
        self._buffer = (ctypes.c_ubyte * 4)()
        if not self._make_current():
            lib.OSMesaDestroyContext(self._ctx)
            raise OSMesaUnavailable("OSMesaMakeCurrent failed")

    def _make_current(self) -> bool:
        return bool(self._lib.OSMesaMakeCurrent(self._ctx, self._buffer, GL_UNSIGNED_BYTE, 1, 1))

    def __enter__(self) -> OSMesaLoader:
        """Make this context current (moderngl's Context.__enter__ calls this)."""
        if self._ctx:
            self._make_current()
        return self

    def __exit__(self, *exc: object) -> None:
        self._lib.OSMesaMakeCurrent(None, None, 0, 0, 0)

    def load_opengl_function(self, name: str) -> int:
        return self._lib.OSMesaGetProcAddress(name.encode()) or 0

    def release(self) -> None:
        if self._ctx:
            self._lib.OSMesaDestroyContext(self._ctx)
            self._ctx = None
