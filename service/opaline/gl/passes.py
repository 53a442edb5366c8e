"""How a job's samples are drawn: jittered passes, each at 1× or 2× the image size.

llvmpipe pays for every pass a fixed cost (vertex work, triangle setup and
binning, the accumulate pass) on top of shading. When the sample count is a
multiple of 4 and the image is small enough, each pass is drawn at twice the
width and height, so one pass gives a 2×2 grid of samples per pixel, and the
resolve averages the 2×2 block: ``samples / 4`` passes instead of ``samples``.
Measured on the 256² presets (docs/speed.md), the standard tier (4 samples)
costs about a third less; MSAA with per-sample shading, measured too, cost
2-3× more on llvmpipe and was not kept. The 2×2 grid replaces the first four
R2 points; pass offsets still come from the R2 sequence, scaled to a sub-pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opaline.model.sampling import sample_offsets

# The largest supersampled target side: 2 × 512 keeps a 1024² float target (21 MB).
MAX_SUPERSAMPLED = 1024


@dataclass(frozen=True)
class SamplePlan:
    """``factor``: the sample target's size over the image's (1 or 2); ``offsets``: each
    pass's jitter in image pixels; ``samples``: all samples per image pixel."""

    factor: int
    offsets: np.ndarray
    samples: int

    @property
    def passes(self) -> int:
        return len(self.offsets)

    @property
    def pass_pixels(self) -> int:
        """The sample-target pixels one image pixel is drawn in over all passes: each
        reads the environment's per-pass samples once."""
        return self.passes * self.factor * self.factor

    def target_size(self, size: tuple[int, int]) -> tuple[int, int]:
        return size[0] * self.factor, size[1] * self.factor

    @property
    def aa_scale(self) -> float:
        """Share of a sample target pixel's width each pass's sample covers (for the
        analytic filter, whose footprint ``fwidth`` measures in sample-target pixels)."""
        return 1.0 / float(np.sqrt(self.passes))


def plan(samples: int, size: tuple[int, int], grid: bool = True) -> SamplePlan:
    """``grid=False``: one sample a pass (each pass then has its own spectral shift)."""
    if grid and samples % 4 == 0 and 2 * max(size) <= MAX_SUPERSAMPLED:
        # Each pass's jitter moves its 2×2 grid within a half-pixel cell.
        return SamplePlan(2, sample_offsets(samples // 4) / 2.0, samples)
    return SamplePlan(1, sample_offsets(samples), samples)


def downsample(linear: np.ndarray, factor: int) -> np.ndarray:
    """Sum each factor×factor block of a (H·f, W·f, C) image: (H, W, C)."""
    if factor == 1:
        return linear
    h, w, c = linear.shape
    # numpy's stubs type a sum over axes as Any; the sum of an array is an array.
    summed: np.ndarray = linear.reshape(h // factor, factor, w // factor, factor, c).sum(axis=(1, 3))
    return summed
