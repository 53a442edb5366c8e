"""Encoders (opaline.output.encode): exact PNGs, 16-bit PNGs built by hand, .npy, MDF display."""

from __future__ import annotations

import io
import struct
import zlib
from types import SimpleNamespace
from typing import get_args

import numpy as np
import pytest
from PIL import Image

from opaline.model.params import ImageFormat
from opaline.output import encode

SIGNATURE = b"\x89PNG\r\n\x1a\n"


def random_display(shape=(13, 17, 4), seed=0) -> np.ndarray:
    return np.random.default_rng(seed).random(shape)


def chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    """Split a PNG into (type, payload), checking every CRC."""
    assert data[:8] == SIGNATURE
    out, pos = [], 8
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        payload = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(kind + payload), kind
        out.append((kind, payload))
        pos += 12 + length
    return out


def decode_png16(data: bytes) -> tuple[dict, np.ndarray]:
    """Parse IHDR and inflate IDAT by hand (filter type 0 rows only)."""
    parts = chunks(data)
    assert parts[0][0] == b"IHDR" and parts[-1] == (b"IEND", b"")
    width, height, depth, colour, compression, filtering, interlace = struct.unpack(
        ">IIBBBBB", parts[0][1])
    header = dict(width=width, height=height, depth=depth, colour=colour,
                  compression=compression, filtering=filtering, interlace=interlace)
    channels = {2: 3, 6: 4}[colour]
    raw = zlib.decompress(b"".join(p for k, p in parts if k == b"IDAT"))
    stride = 1 + width * channels * 2
    assert len(raw) == height * stride
    rows = np.frombuffer(raw, np.uint8).reshape(height, stride)
    assert np.all(rows[:, 0] == 0), "only filter type 0 is expected"
    values = rows[:, 1:].copy().view(">u2").reshape(height, width, channels).astype(np.uint16)
    return header, values


def test_quantise_rounds_to_nearest_and_clamps():
    """Quantisation rounds to nearest and clamps out-of-range values."""
    x = np.array([-0.5, 0.0, 0.49 / 255, 0.51 / 255, 1.0, 2.0, np.nextafter(1.0, 0.0)])
    assert encode.quantise(x, 8).tolist() == [0, 0, 0, 1, 255, 255, 255]
    assert encode.quantise(x, 8).dtype == np.uint8
    assert encode.quantise(x, 16).dtype == np.uint16
    assert encode.quantise(np.array([1.0]), 16).tolist() == [65535]


@pytest.mark.parametrize("alpha", [False, True])
def test_png8_round_trips_exactly(alpha):
    """Values on the 8-bit grid come back from Pillow unchanged."""
    levels = np.random.default_rng(1).integers(0, 256, size=(11, 19, 4))
    image = Image.open(io.BytesIO(encode.png8(levels / 255.0, alpha)))
    assert image.format == "PNG"
    assert image.mode == ("RGBA" if alpha else "RGB")
    assert image.size == (19, 11)
    channels = 4 if alpha else 3
    assert np.array_equal(np.asarray(image), levels[..., :channels])


def test_png8_rounds_in_between_values():
    """Arbitrary floats are written as round(x·255)."""
    display = random_display(seed=2)
    got = np.asarray(Image.open(io.BytesIO(encode.png8(display, True))))
    assert np.array_equal(got, np.round(display * 255).astype(np.uint8))


@pytest.mark.parametrize("alpha", [False, True])
def test_png16_is_valid_16_bit_png(alpha):
    """png16 has a 16-bit IHDR and IDAT samples equal to round(x·65535)."""
    display = random_display(seed=3)
    display[0, 0] = [0.0, 0.5, 1.0, 0.25]
    header, values = decode_png16(encode.png16(display, alpha))
    assert header == dict(width=17, height=13, depth=16, colour=6 if alpha else 2,
                          compression=0, filtering=0, interlace=0)
    channels = 4 if alpha else 3
    expected = np.round(display[..., :channels] * 65535).astype(np.uint16)
    assert np.array_equal(values, expected)
    assert values[0, 0, 2] == 65535 and values[0, 0, 0] == 0


def test_png16_opens_in_pillow():
    """Pillow accepts the hand-built 16-bit PNG at the right size."""
    image = Image.open(io.BytesIO(encode.png16(random_display(seed=4), True)))
    image.load()
    assert image.size == (17, 13)


def test_png_alpha_is_kept_only_when_asked():
    """With alpha the 4th channel is written; without it, RGB only and alpha ignored."""
    display = np.full((16, 16, 4), 0.5)
    display[..., 3] = np.linspace(0, 1, 16)[None, :]
    with_alpha = np.asarray(Image.open(io.BytesIO(encode.png8(display, True))))
    ramp = np.round(np.linspace(0, 1, 16) * 255).astype(np.uint8)
    assert np.array_equal(with_alpha[0, :, 3], ramp)
    without = encode.png8(display, False)
    other_alpha = display.copy()
    other_alpha[..., 3] = 0.0
    assert encode.png8(other_alpha, False) == without
    assert decode_png16(encode.png16(display, False))[1].shape[-1] == 3


def test_npy_round_trips():
    """npy bytes load back with np.load as the same float32 array."""
    linear = random_display((9, 7, 4), seed=5) * 30.0
    back = np.load(io.BytesIO(encode.npy(linear)), allow_pickle=False)
    assert back.dtype == np.float32 and back.shape == (9, 7, 4)
    assert np.array_equal(back, linear.astype(np.float32))


def test_npy_keeps_values_beyond_display_range():
    """Linear output is not clamped: HDR and tiny values survive."""
    linear = np.array([[[0.0, 1e-30, 1.0, 1e4]]], dtype=np.float32)
    assert np.array_equal(np.load(io.BytesIO(encode.npy(linear))), linear)


@pytest.mark.parametrize("fmt", ["png", "png16", "npy"])
def test_same_input_same_bytes(fmt):
    """Encoding the same frame twice gives identical bytes."""
    frame = SimpleNamespace(linear=random_display(seed=6).astype(np.float32),
                            display=random_display(seed=6))
    first = encode.encode_frame(frame, fmt, alpha=True)
    second = encode.encode_frame(SimpleNamespace(linear=frame.linear.copy(),
                                                 display=frame.display.copy()), fmt, alpha=True)
    assert first == second


def test_encode_frame_dispatches_by_format():
    """encode_frame writes linear data to npy and display data to the PNGs."""
    frame = SimpleNamespace(linear=np.full((16, 16, 4), 7.0, np.float32),
                            display=np.full((16, 16, 4), 0.5))
    assert np.all(np.load(io.BytesIO(encode.encode_frame(frame, "npy"))) == 7.0)
    assert decode_png16(encode.encode_frame(frame, "png16"))[0]["depth"] == 16
    png = Image.open(io.BytesIO(encode.encode_frame(frame, "png")))
    assert png.mode == "RGB" and np.asarray(png)[0, 0, 0] == 128
    assert set(encode.MEDIA_TYPES) == set(encode.EXTENSIONS) == set(get_args(ImageFormat))


def test_mdf_display_peaks_at_one():
    """The display MDF plot is normalised: its maximum is 1 and it keeps the ordering."""
    plot = np.random.default_rng(7).random((16, 16, 3)) * 123.0
    shown = encode.mdf_display(plot)
    assert shown.dtype == np.float32
    assert shown.max() == pytest.approx(1.0, abs=1e-6)
    assert shown.min() >= 0.0
    order = np.argsort(plot.ravel(), kind="stable")
    assert np.all(np.diff(shown.ravel()[order]) >= 0.0)


def test_mdf_display_of_zero_plot_is_black():
    """An all-zero plot stays zero (no division by zero)."""
    shown = encode.mdf_display(np.zeros((16, 16, 3)))
    assert np.all(shown == 0.0)


def test_encode_mdf_is_linear_npy_or_normalised_png():
    """encode_mdf keeps linear D in npy and writes the normalised display plot as an RGB PNG."""
    plot = np.random.default_rng(8).random((16, 16, 3)).astype(np.float32) * 40.0
    assert np.array_equal(np.load(io.BytesIO(encode.encode_mdf(plot, "npy"))), plot)
    png = encode.encode_mdf(plot, "png")
    assert png == encode.png8(encode.mdf_display(plot), alpha=False)
    assert Image.open(io.BytesIO(png)).mode == "RGB"
