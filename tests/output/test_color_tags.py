"""A wide-gamut image says what it is (output/color_tags.py): PNG's cICP and iCCP chunks,
the ICC profile in WebP, AVIF and JPEG, and LittleCMS (through Pillow) reading that
profile converts the pixels as the float64 twin does."""

from __future__ import annotations

import io
import struct

import numpy as np
import pytest
from PIL import Image, ImageCms

from opaline.model import color_space
from opaline.output.color_tags import icc_profile
from opaline.output.encode import png16, png_pixels
from opaline.output.formats import encode_pillow

WIDE = ("display-p3", "rec2020")


def chunks(png: bytes) -> list[tuple[bytes, bytes]]:
    out, at = [], 8
    while at < len(png):
        (length,) = struct.unpack(">I", png[at:at + 4])
        out.append((png[at + 4:at + 8], png[at + 8:at + 8 + length]))
        at += 12 + length
    return out


def pixels() -> np.ndarray:
    return np.random.default_rng(5).integers(0, 256, (48, 48, 3), dtype=np.uint8)


@pytest.mark.parametrize(("space", "cicp"), [("display-p3", (12, 13, 0, 1)),
                                             ("rec2020", (9, 1, 0, 1))])
def test_a_wide_png_carries_cicp_and_its_profile_before_the_pixels(space, cicp):
    for png in (png_pixels(pixels(), space), png16(pixels() / 255.0, False, space)):
        kinds = [kind for kind, _ in chunks(png)]
        assert kinds[:3] == [b"IHDR", b"cICP", b"iCCP"] and b"sRGB" not in kinds
        assert tuple(dict(chunks(png))[b"cICP"]) == cicp
        assert Image.open(io.BytesIO(png)).info["icc_profile"] == icc_profile(space)


def test_an_srgb_png_keeps_its_srgb_chunk_alone():
    kinds = [kind for kind, _ in chunks(png_pixels(pixels()))]
    assert kinds == [b"IHDR", b"sRGB", b"IDAT", b"IEND"]


@pytest.mark.parametrize("fmt", ["webp", "webp-lossless", "avif", "jpeg"])
@pytest.mark.parametrize("space", WIDE)
def test_pillow_formats_carry_the_profile(fmt, space):
    encoded = encode_pillow(pixels(), fmt, icc_profile(space))
    assert Image.open(io.BytesIO(encoded)).info.get("icc_profile") == icc_profile(space)


@pytest.mark.parametrize("space", WIDE)
def test_littlecms_reads_the_profile_as_the_twin_converts(space):
    """Pixels in ``space`` converted to sRGB by LittleCMS through the file's own profile,
    against the twin's matrices and curves, over the pixels that sRGB holds: within one
    8-bit level (the profiles are the spaces' exact primaries and curves)."""
    image = Image.open(io.BytesIO(png_pixels(pixels(), space)))
    profile = ImageCms.ImageCmsProfile(io.BytesIO(image.info["icc_profile"]))
    transform = ImageCms.buildTransform(profile, ImageCms.createProfile("sRGB"), "RGB", "RGB",
                                        renderingIntent=ImageCms.Intent.RELATIVE_COLORIMETRIC)
    theirs = np.asarray(ImageCms.applyTransform(image, transform), dtype=np.float64)
    linear = color_space.decode(pixels() / 255.0, space) @ np.linalg.inv(
        color_space.from_srgb(space)).T
    inside = (linear.min(axis=-1) >= 0.0) & (linear.max(axis=-1) <= 1.0)
    assert inside.mean() > 0.3
    ours = color_space.encode(linear, "srgb") * 255.0
    assert np.abs(theirs - ours)[inside].max() <= 1.0
