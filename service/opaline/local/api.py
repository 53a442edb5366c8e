"""``from opaline import render``: one call, a request in, image bytes out (docs/python.md).

    from opaline import render
    from opaline import render_array
    png = render({"preset": "cd-rom", "mu_f": 6, "width": 128, "height": 128})
    linear = render_array({"preset": "nacre"})          # (H, W, 4) float32

Each thread gets its own ``pipeline.LocalRenderer`` (a GL context is current
on one thread only), made on first use and kept for the next call; ``close()``
releases the calling thread's renderer, and a thread that ends releases its own.
Invalid requests raise ``RequestError`` (one line per field: name, value, allowed
range); an unknown preset raises ``presets.UnknownPreset``; a request over the cost
budget ``request.CostError``.
"""

from __future__ import annotations

import os
import threading
import weakref
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from pydantic import ValidationError

from opaline.local.pipeline import LocalRenderer
from opaline.model.params import RenderRequest, describe_errors
from opaline.model.strict_json import validate_strictly
from opaline.settings import BackendName

# A request model, its fields as a mapping, or the path of a material file (.toml/.json).
RequestLike = RenderRequest | Mapping[str, Any] | str | os.PathLike[str]
MATERIAL_SUFFIXES = (".toml", ".json")


class RequestError(ValueError):
    """The request is invalid; ``problems`` holds one line per field (name, value, range)."""

    def __init__(self, problems: list[str]) -> None:
        self.problems = problems
        super().__init__("; ".join(problems))


_local = threading.local()


def as_request(request: RequestLike) -> RenderRequest:
    """A RenderRequest from a model, a mapping of its fields, or a material file's path.

    A ``str`` is a path only when it ends in .toml or .json: a bare name such as
    ``"cd-rom"`` is refused rather than guessed to be a preset or a file."""
    if isinstance(request, RenderRequest):
        return request
    if isinstance(request, str) and not request.lower().endswith(MATERIAL_SUFFIXES):
        raise TypeError(f"render({request!r}): a str must be a material file's path "
                        f"(.toml or .json); for a preset pass {{'preset': {request!r}}}")
    if isinstance(request, str | os.PathLike):
        from opaline.model.materials import MaterialError, load_material

        try:
            return load_material(Path(request))
        except MaterialError as exc:
            raise RequestError([str(exc)]) from None
    if not isinstance(request, Mapping):
        raise TypeError("expected a RenderRequest, a mapping, or a material file's path, "
                        f"got {type(request).__name__}")
    try:  # as a JSON body is read: {"mu_f": "6"} and {"mu_f": True} are refused there too
        return validate_strictly(dict(request), RenderRequest)
    except ValidationError as exc:
        raise RequestError(describe_errors(exc)) from None


def renderer(backend: BackendName | None = None) -> LocalRenderer:
    """This thread's renderer, created on first use (or anew for a different ``backend``:
    one context per thread, and EGL and OSMesa should not share a process anyway)."""
    found: LocalRenderer | None = getattr(_local, "renderer", None)
    if found is not None and getattr(_local, "backend", None) != backend:
        close()
        found = None
    if found is None:
        found = LocalRenderer(backend)
        _local.renderer, _local.backend = found, backend
        # Released when the thread ends, should it never call close(): the thread's locals
        # are dropped on that thread as it exits, where the context is current. Not at the
        # interpreter's exit, which runs on the main thread, not the context's.
        _local.ends = end = _ThreadEnd()
        _local.release = weakref.finalize(end, _release, found, os.getpid(),
                                          threading.get_ident())
        _local.release.atexit = False
    return found


def render(request: RequestLike, *, backend: BackendName | None = None) -> bytes:
    """Encoded image bytes (PNG, 16-bit PNG or .npy, as the request's ``format`` says)."""
    return renderer(backend).render_bytes(as_request(request))


def render_array(
    request: RequestLike, *, backend: BackendName | None = None
) -> npt.NDArray[np.float32]:
    """Linear, premultiplied RGBA float32 of shape (height, width, 4)."""
    return renderer(backend).render_array(as_request(request))


def close() -> None:
    """Release the calling thread's renderer and its GL context (also done when the
    thread ends)."""
    release = getattr(_local, "release", None)
    _local.renderer = _local.backend = _local.ends = _local.release = None
    if release is not None:
        release()  # at most once: a finalizer called is dead


def _release(found: LocalRenderer, pid: int, thread: int) -> None:
    """``found.close()`` on the thread and in the process that made it: a fork drops the
    other threads' locals in the child, on its main thread, whose GL state is a copy."""
    if os.getpid() == pid and threading.get_ident() == thread:
        found.close()


class _ThreadEnd:
    """Held only in a thread's locals: collected when the thread ends."""
