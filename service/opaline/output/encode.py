"""Encoders: PNG (8- and 16-bit) and ``.npy``; WebP, AVIF and JPEG in ``formats``.

8-bit images arrive as bytes resolved in GL (``Frame.pixels``); 16-bit and
linear ones as float. PNGs are built here: fixed chunks, the "up" filter on
every row and deflate at level 1 by ISA-L (``isal``), so the same render always
gives the same bytes. Measured on the presets (docs/speed.md): ISA-L level 1 is
5-7× faster than zlib level 1 and no larger; zlib level 6 was 2-8× slower
still for 5-20 % fewer bytes. Without ``isal`` (a platform with no wheel),
zlib level 1 writes the same images in other bytes.
"""

from __future__ import annotations

import io
import struct
import zlib
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from opaline.output.color_tags import icc_profile, png_chunks
from opaline.output.formats import LOSSY, encode_pillow

if TYPE_CHECKING:
    from opaline.gl.buffers import Frame

# Either module: both have compress(data, level).
deflater: ModuleType
try:
    from isal import isal_zlib as deflater
except ImportError:  # pragma: no cover - isal is a dependency; zlib is the fallback
    deflater = zlib

MEDIA_TYPES = {"png": "image/png", "png16": "image/png", "npy": "application/x-npy",
               "webp": "image/webp", "webp-lossless": "image/webp", "avif": "image/avif",
               "jpeg": "image/jpeg"}
EXTENSIONS = {"png": ".png", "png16": ".png", "npy": ".npy", "webp": ".webp",
              "webp-lossless": ".webp", "avif": ".avif", "jpeg": ".jpg"}
PNG_LEVEL = 1
SIGNATURE = b"\x89PNG\r\n\x1a\n"


def quantise(display: np.ndarray, bits: int) -> np.ndarray:
    top = (1 << bits) - 1
    scaled: np.ndarray = np.rint(np.clip(display, 0.0, 1.0) * top)
    return scaled.astype(np.uint8 if bits == 8 else np.uint16)


def _chunk(kind: bytes, payload: bytes) -> bytes:
    body = kind + payload
    return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body))


def _png(rows: bytes, width: int, height: int, depth: int, channels: int,
         space: str = "srgb") -> bytes:
    colour_type = 6 if channels == 4 else 2
    header = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    tags = b"".join(_chunk(kind, payload) for kind, payload in png_chunks(space))
    return (SIGNATURE + _chunk(b"IHDR", header) + tags
            + _chunk(b"IDAT", deflater.compress(rows, PNG_LEVEL)) + _chunk(b"IEND", b""))


def png_pixels(pixels: np.ndarray, space: str = "srgb") -> bytes:
    """8-bit RGB or RGBA (H, W, C) uint8, every row filtered "up" (type 2), tagged as
    ``space``."""
    height, width, channels = pixels.shape
    flat = pixels.reshape(height, width * channels)
    rows = np.empty((height, 1 + width * channels), np.uint8)
    rows[:, 0] = 2
    rows[0, 1:] = flat[0]  # the row above the first is zero
    np.subtract(flat[1:], flat[:-1], out=rows[1:, 1:])  # wraps modulo 256, as PNG wants
    return _png(rows.tobytes(), width, height, 8, channels, space)


def png8(display: np.ndarray, alpha: bool) -> bytes:
    """8-bit PNG from float display values (MDF plots; tests)."""
    return png_pixels(quantise(display[..., :4 if alpha else 3], 8))


def png16(display: np.ndarray, alpha: bool, space: str = "srgb") -> bytes:
    """16 bits per channel (filter type 0), from float display values."""
    channels = 4 if alpha else 3
    data = quantise(display[..., :channels], 16).astype(">u2")
    height, width = data.shape[:2]
    rows = np.concatenate(
        [np.zeros((height, 1), np.uint8), data.view(np.uint8).reshape(height, -1)], 1
    )
    return _png(rows.tobytes(), width, height, 16, channels, space)


def npy(array: np.ndarray) -> bytes:
    out = io.BytesIO()
    np.save(out, np.ascontiguousarray(array, dtype=np.float32), allow_pickle=False)
    return out.getvalue()


def encode_frame(frame: Frame, fmt: str, alpha: bool = False, space: str = "srgb") -> bytes:
    """The frame in ``fmt``, its display values (or, for npy, linear values) in ``space``,
    which the file names."""
    if fmt == "npy":
        assert frame.linear is not None  # the renderer reads linear pixels for npy
        return npy(frame.linear)
    if fmt == "png16":
        assert frame.display is not None  # and display values for 16 bits
        return png16(frame.display, alpha, space)
    pixels = getattr(frame, "pixels", None)
    if pixels is None:  # a float frame (the Python API's arrays, tests)
        assert frame.display is not None  # a frame without pixels has display values
        pixels = quantise(frame.display[..., :4 if alpha else 3], 8)
    if fmt == "png":
        return png_pixels(pixels, space)
    return encode_pillow(pixels, fmt, icc_profile(space))


def mdf_display(plot: np.ndarray) -> np.ndarray:
    """An MDF plot for viewing: normalised by its maximum, then sRGB encoded."""
    from opaline.model.reference import srgb_encode

    peak = float(plot.max())
    scaled = plot / peak if peak > 0 else plot
    return srgb_encode(scaled).astype(np.float32)


def encode_mdf(plot: np.ndarray, fmt: str) -> bytes:
    """An MDF plot as ``npy`` (linear D) or, for any other format, a normalised 8-bit PNG."""
    return npy(plot) if fmt == "npy" else png8(mdf_display(plot), alpha=False)


__all__ = ["EXTENSIONS", "LOSSY", "MEDIA_TYPES", "encode_frame", "encode_mdf", "npy", "png16",
           "png8", "png_pixels", "quantise"]
