"""A transparent turntable keeps its alpha in WebP, the one animation format with one, and
is refused in GIF and MP4 (before, every format drew the backdrop opaque black)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image
from pydantic import ValidationError

from opaline.local.turntable import turntable_bytes
from opaline.model.turntable import TurntableRequest
from opaline.workers.animation_task import AnimationTask


def alpha_of_frames(data: bytes) -> list[np.ndarray]:
    with Image.open(io.BytesIO(data)) as image:
        found = []
        for index in range(image.n_frames):
            image.seek(index)
            found.append(np.asarray(image.convert("RGBA"))[..., 3])
    return found


@pytest.mark.parametrize("animation", ["gif", "mp4"])
def test_transparent_is_refused_without_alpha(animation):
    with pytest.raises(ValidationError, match="no alpha channel: transparent=true needs "
                                              "animation=webp"):
        TurntableRequest(preset="cd-rom", transparent=True, animation=animation)
    TurntableRequest(preset="cd-rom", transparent=False, animation=animation)


def test_the_worker_encodes_rgba_frames_with_their_alpha():
    frames = []
    for shade in (60, 120):
        pixels = np.full((16, 24, 4), shade, np.uint8)
        pixels[:, :12, 3] = 0  # the left half is backdrop
        pixels[:, 12:, 3] = 255
        out = io.BytesIO()
        Image.fromarray(pixels, "RGBA").save(out, format="PNG")
        frames.append(out.getvalue())
    data = AnimationTask(tuple(frames), "webp", 10).run(None, lambda: False)
    for alpha in alpha_of_frames(data):
        assert alpha[:, :10].max() == 0 and alpha[:, 14:].min() == 255


@pytest.mark.gl
def test_a_transparent_turntable_shows_the_backdrop_through(local):
    request = TurntableRequest(preset="sphere", quality="draft", frames=2, width=32, height=32,
                               transparent=True)
    for alpha in alpha_of_frames(turntable_bytes(local, request)):
        assert alpha[0, 0] == 0  # the corner is backdrop
        assert np.count_nonzero(alpha == 255) > 100  # the ball is opaque
