"""Turntables: N frames of one request, the camera stepping once around the target.

A turntable is a render request plus ``frames``, ``fps`` and the animation
format. Each frame is an ordinary ``Job`` with its own ``camera_azimuth``
(so frames are cached, deduplicated and admitted like any render) and the
cost budget covers all of them together.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Annotated, Literal

from pydantic import Field, ValidationInfo, field_validator

from opaline.model.meshes import MESH_VIEW, is_mesh
from opaline.model.params import RenderRequest
from opaline.model.presets import Preset
from opaline.model.request import CostError, Job

AnimationFormat = Literal["webp", "gif", "mp4"]


class TurntableRequest(RenderRequest):
    """A render request turned into an animation around the object."""

    frames: Annotated[int, Field(ge=2, le=360)] = Field(
        36, description="Frames in one turn, 2 … 360.")
    fps: Annotated[int, Field(ge=1, le=60)] = Field(24, description="Frames per second, 1 … 60.")
    animation: AnimationFormat = Field(
        "webp", description="'webp' (animated WebP, the one with an alpha channel: "
                            "transparent=true), 'gif' or 'mp4' (H.264, yuv420p: an odd width or height "
                            "gains one edge pixel).")

    @field_validator("animation")
    @classmethod
    def _alpha_only_in_webp(cls, animation: str, info: ValidationInfo) -> str:
        # GIF's one transparent palette entry and H.264's lack of alpha would draw a
        # transparent backdrop black, so such a turntable is refused, not degraded.
        if info.data.get("transparent") and animation != "webp":
            raise ValueError("a GIF or an MP4 has no alpha channel: transparent=true needs "
                             "animation=webp")
        return animation


    def still(self) -> RenderRequest:
        """The request of one frame (what resolves to the frames' common job)."""
        return RenderRequest(**self.model_dump(exclude={"frames", "fps", "animation"},
                                               exclude_none=True))


def start_azimuth(job: Job, preset: Preset) -> float:
    """Where the turn starts: the job's azimuth, else the view the still image has."""
    if job.camera_azimuth is not None:
        return job.camera_azimuth
    if is_mesh(preset):
        return MESH_VIEW[0]
    eye, target = preset.camera.eye, preset.camera.target
    return math.degrees(math.atan2(eye[2] - target[2], eye[0] - target[0]))


def frame_jobs(job: Job, preset: Preset, frames: int) -> list[Job]:
    """One job per frame, evenly around the circle, as PNG (the encoder decodes them)."""
    start = start_azimuth(job, preset)
    return [replace(job, format="png", camera_azimuth=(start + 360.0 * i / frames + 180.0)
                    % 360.0 - 180.0) for i in range(frames)]


def check_turntable_cost(job: Job, frames: int, budget: int) -> None:
    total = job.cost * frames
    if total > budget:
        raise CostError(
            f"cost={total} (frames×width×height×samples×max(wavelengths, 3) = {frames}×"
            f"{job.width}×{job.height}×{job.samples}×{max(job.wavelengths, 3)}) is over the "
            f"budget of {budget}: lower the frames, size, samples or wavelengths")
