"""The last stage: a prepared job drawn by a renderer and encoded in the job's format.

Run in the process that owns the GL context (a worker, or the caller's own for
the CLI and the Python API); the renderer is whatever draws frames there.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from opaline.model.presets import Preset
from opaline.model.request import Job
from opaline.output.encode import encode_frame
from opaline.pipeline.prepare import Prepared

StopCheck = Callable[[], bool]


class FrameRenderer(Protocol):
    def render(self, job: Job, preset: Preset | None = None, all_features: bool = False,
               should_stop: StopCheck | None = None) -> Any: ...  # gl.buffers.Frame


def produce(prepared: Prepared, renderer: FrameRenderer,
            should_stop: StopCheck | None = None) -> bytes:
    job = prepared.job
    frame = renderer.render(job, prepared.preset, should_stop=should_stop)
    return encode_frame(frame, job.format, alpha=job.transparent, space=job.color_space)
