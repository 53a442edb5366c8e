"""Turntable encoders: frames (H, W, 3 or 4 uint8 sRGB) to animated WebP, GIF or MP4, and back.

WebP and GIF through Pillow; MP4 (H.264, yuv420p, the format every browser
and editor plays) through imageio-ffmpeg, which ships its own ffmpeg binary
in the wheel. ``decode`` reads an animation back (frame count and size) for
tests and for clients that check what they got.
"""

from __future__ import annotations

import io
import os

import numpy as np
from PIL import Image

from opaline import scratch

ANIMATION_FORMATS = ("webp", "gif", "mp4")
MEDIA_TYPES = {"webp": "image/webp", "gif": "image/gif", "mp4": "video/mp4"}
EXTENSIONS = {"webp": ".webp", "gif": ".gif", "mp4": ".mp4"}
# Seconds an encode takes per megapixel-frame, the frames' PNGs read back included
# (0.02): measured at 36 frames of 256² and 512² (a gradient with noise, 2-core machine
# under load): webp 0.13-0.14, gif 0.02, mp4 0.19-0.26 (x264 on both cores). Admission
# adds its safety factor; 360 frames at 860² are about 266 megapixel-frames.
ENCODE_S_PER_MPX = {"webp": 0.16, "gif": 0.045, "mp4": 0.28}


def encode_cost_s(frames: int, width: int, height: int, fmt: str) -> float:
    """Predicted seconds to encode ``frames`` frames of ``width`` × ``height`` as ``fmt``."""
    return frames * width * height / 1e6 * ENCODE_S_PER_MPX[fmt]


def encode(frames: list[np.ndarray], fmt: str, fps: int) -> bytes:
    if fmt not in ANIMATION_FORMATS:
        raise ValueError(f"animation format {fmt!r}: choose one of {', '.join(ANIMATION_FORMATS)}")
    if not frames:
        raise ValueError("an animation needs at least one frame")
    if fmt == "mp4":
        return _mp4(frames, fps)
    # WebP keeps a transparent backdrop's alpha; the request refuses it for the others.
    channels = 4 if fmt == "webp" and frames[0].shape[-1] == 4 else 3
    images = [Image.fromarray(np.ascontiguousarray(f[..., :channels])) for f in frames]
    out = io.BytesIO()
    duration = max(1, round(1000 / fps))
    if fmt == "gif":
        # One adaptive palette per frame: the iridescent colours change as the object turns.
        images = [im.quantize(colors=256, method=Image.Quantize.FASTOCTREE) for im in images]
        images[0].save(out, format="GIF", save_all=True, append_images=images[1:],
                       duration=duration, loop=0, disposal=1, optimize=False)
    else:
        # With alpha, every frame a key frame: libwebp's lossy sub-frames, cropped to
        # where a frame changed, left the canvas without its alpha flag, and decoders
        # drew the transparent backdrop opaque black.
        keys = {"kmax": 1} if channels == 4 else {}
        images[0].save(out, format="WEBP", save_all=True, append_images=images[1:],
                       duration=duration, loop=0, quality=85, method=4, **keys)
    return out.getvalue()


def _mp4(frames: list[np.ndarray], fps: int) -> bytes:
    import imageio_ffmpeg

    height, width = frames[0].shape[:2]
    # yuv420p needs even sizes: pad by a row or column of the edge's colour.
    pad = ((0, height % 2), (0, width % 2), (0, 0))
    # ffmpeg writes the file by name (its faststart pass rewrites it); the name is locked
    # while this process lives, so what a killed encode left the next encode sweeps.
    scratch.sweep("encode")
    fd, path = scratch.owned_file("encode", ".mp4")
    try:
        writer = imageio_ffmpeg.write_frames(
            str(path), (width + width % 2, height + height % 2), fps=fps, codec="libx264",
            pix_fmt_out="yuv420p", quality=8, macro_block_size=1,
            output_params=["-movflags", "+faststart"])
        writer.send(None)
        for frame in frames:
            writer.send(np.ascontiguousarray(np.pad(frame[..., :3], pad, mode="edge")))
        writer.close()
        with open(path, "rb") as stream:
            return stream.read()
    finally:
        scratch.release(fd, path)


def decode(data: bytes, fmt: str) -> tuple[int, tuple[int, int]]:
    """(frame count, (width, height)) of an encoded animation."""
    if fmt == "mp4":
        import imageio_ffmpeg

        fd, path = scratch.owned_file("decode", ".mp4")
        try:
            with os.fdopen(os.dup(fd), "wb") as stream:
                stream.write(data)
            reader = imageio_ffmpeg.read_frames(str(path))
            meta = reader.__next__()
            count = sum(1 for _ in reader)
            return count, tuple(meta["size"])
        finally:
            scratch.release(fd, path)
    with Image.open(io.BytesIO(data)) as image:
        return getattr(image, "n_frames", 1), image.size
