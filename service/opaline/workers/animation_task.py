"""Encode a turntable's frames in a worker: the HTTP process never runs an encoder.

The frames arrive as the PNGs the frame renders answered (and the image
cache holds), so a repeated turntable costs one encode and no render."""

from __future__ import annotations

import io
import struct
from dataclasses import dataclass
from typing import Any

import numpy as np
from PIL import Image

from opaline.output.animation import encode, encode_cost_s
from opaline.workers.tasks import StopCheck

ENCODE_LABEL = "animation"


@dataclass(frozen=True)
class AnimationTask:
    frames: tuple[bytes, ...]
    fmt: str
    fps: int
    label: str = ENCODE_LABEL

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        frames = [np.asarray(_rgb_or_rgba(Image.open(io.BytesIO(png)))) for png in self.frames]
        return encode(frames, self.fmt, self.fps)

    def units(self) -> tuple[str, float, int, float]:
        """The encode's own predicted seconds (``encode_cost_s``): counted as work ahead."""
        first = self.frames[0] if self.frames else b""
        # a PNG's size is in its header (IHDR, bytes 16-24)
        width, height = struct.unpack(">II", first[16:24]) if len(first) >= 24 else (0, 0)
        return ENCODE_LABEL, 0.0, 0, encode_cost_s(len(self.frames), width, height, self.fmt)


def _rgb_or_rgba(image: Image.Image) -> Image.Image:
    """A transparent render's frame keeps its alpha (WebP encodes it), any other is RGB."""
    return image.convert("RGBA" if "A" in image.getbands() else "RGB")
