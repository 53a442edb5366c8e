"""Encoders: 8-bit and 16-bit PNG from display values, ``.npy`` from linear float.

Quantisation rounds to nearest and PNG metadata is fixed, so the same render
always gives the same bytes.
"""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np
from PIL import Image

MEDIA_TYPES = {"png": "image/png", "png16": "image/png", "npy": "application/x-npy"}
EXTENSIONS = {"png": ".png", "png16": ".png", "npy": ".npy"}


def quantise(display: np.ndarray, bits: int) -> np.ndarray:
    top = (1 << bits) - 1
    scaled = np.rint(np.clip(display, 0.0, 1.0) * top)
    return scaled.astype(np.uint8 if bits == 8 else np.uint16)


def png8(display: np.ndarray, alpha: bool) -> bytes:
    channels = 4 if alpha else 3
    image = Image.fromarray(quantise(display[..., :channels], 8), "RGBA" if alpha else "RGB")
    out = io.BytesIO()
    image.save(out, format="PNG", compress_level=6)
    return out.getvalue()


def png16(display: np.ndarray, alpha: bool) -> bytes:
    """16 bits per channel. Pillow cannot write 16-bit RGB, so the PNG is built with zlib."""
    channels = 4 if alpha else 3
    data = quantise(display[..., :channels], 16).astype(">u2")
    height, width = data.shape[:2]
    rows = np.concatenate(
        [np.zeros((height, 1), np.uint8), data.view(np.uint8).reshape(height, -1)], 1
    )

    def chunk(kind: bytes, payload: bytes) -> bytes:
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body))

    colour_type = 6 if alpha else 2
    header = struct.pack(">IIBBBBB", width, height, 16, colour_type, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"sRGB", b"\x00")
        + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
        + chunk(b"IEND", b"")
    )


def npy(array: np.ndarray) -> bytes:
    out = io.BytesIO()
    np.save(out, np.ascontiguousarray(array, dtype=np.float32), allow_pickle=False)
    return out.getvalue()


def encode_frame(frame, fmt: str, alpha: bool = False) -> bytes:
    if fmt == "npy":
        return npy(frame.linear)
    if fmt == "png16":
        return png16(frame.display, alpha)
    return png8(frame.display, alpha)


def mdf_display(plot: np.ndarray) -> np.ndarray:
    """An MDF plot for viewing: normalised by its maximum, then sRGB encoded."""
    from opaline.model.reference import srgb_encode

    peak = float(plot.max())
    scaled = plot / peak if peak > 0 else plot
    return srgb_encode(scaled).astype(np.float32)


def encode_mdf(plot: np.ndarray, fmt: str) -> bytes:
    """An MDF plot as ``npy`` (linear D) or, for any other format, a normalised 8-bit PNG."""
    return npy(plot) if fmt == "npy" else png8(mdf_display(plot), alpha=False)
