"""Turntables without HTTP: ``render_turntable`` in Python, ``opaline turntable`` on the CLI.

    from opaline.local.turntable import render_turntable
    webp = render_turntable({"preset": "cd-rom", "frames": 36, "animation": "webp"})

Frames render one after another on the calling thread's renderer (as
``opaline.render``), ``progress(done, total)`` is called after each, and the
encoder (``opaline.output.animation``) makes the file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from pydantic import ValidationError

from opaline.local.api import RequestError, renderer
from opaline.local.pipeline import LocalRenderer, budget_of, prepare_locally
from opaline.model.params import describe_errors
from opaline.model.strict_json import validate_strictly
from opaline.model.turntable import TurntableRequest, check_turntable_cost, frame_jobs
from opaline.output.animation import encode
from opaline.output.encode import quantise
from opaline.pipeline.prepare import Prepared
from opaline.settings import BackendName

Progress = Callable[[int, int], None]


def as_turntable(request: TurntableRequest | Mapping[str, Any]) -> TurntableRequest:
    if isinstance(request, TurntableRequest):
        return request
    try:
        # As render() and a JSON body read it: {"mu_f": "6"} and {"mu_f": True} refused.
        return validate_strictly(dict(request), TurntableRequest)
    except ValidationError as exc:
        raise RequestError(describe_errors(exc, TurntableRequest)) from None


def render_turntable(request: TurntableRequest | Mapping[str, Any], *,
                     backend: BackendName | None = None,
                     progress: Progress | None = None) -> bytes:
    """The encoded animation (WebP, GIF or MP4 as ``animation`` says)."""
    return turntable_bytes(renderer(backend), as_turntable(request), progress)


def prepare_turntable(request: TurntableRequest, cost_budget: int | None = None) -> Prepared:
    """The frames' common job, checked against the limits and the budget over all frames;
    no GL, so the CLI checks before it opens a context."""
    prepared = prepare_locally(request.still(), cost_budget)
    check_turntable_cost(prepared.job, request.frames, budget_of(cost_budget))
    return prepared


def turntable_bytes(local: LocalRenderer, request: TurntableRequest,
                    progress: Progress | None = None, prepared: Prepared | None = None) -> bytes:
    """The animation; ``prepared``: ``prepare_turntable``'s answer, if already had."""
    prepared = prepared or prepare_turntable(request, local.cost_budget)
    preset, job = prepared.preset, prepared.job
    frames: list[np.ndarray] = []
    jobs = frame_jobs(job, preset, request.frames)
    for index, frame_job in enumerate(jobs, 1):
        frame = local.renderer.render(frame_job, preset)
        pixels = frame.pixels
        if pixels is None:
            assert frame.display is not None  # a frame without 8-bit pixels has display values
            pixels = quantise(frame.display, 8)
        frames.append(np.ascontiguousarray(pixels))  # RGBA where transparent (WebP keeps it)
        if progress is not None:
            progress(index, len(jobs))
    return encode(frames, request.animation, request.fps)
