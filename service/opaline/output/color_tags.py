"""What an image file says about its colour space, for an output in Display P3 or
Rec. 2020 (an sRGB image keeps PNG's sRGB chunk, and Pillow's formats their default).

ICC profiles: Clinton Ingram's compact v4 profiles (github.com/saucecontrol/
Compact-ICC-Profiles, CC0: ``DisplayP3-v4.icc`` and ``Rec2020-v4.icc``, the exact
primaries and parametric curves; 480 bytes each), shipped in ``icc/``. LittleCMS, reading
them through Pillow, converts our Display P3 and Rec. 2020 pixels to sRGB within 0.65 of
an 8-bit level of the float64 twin (tests/output/test_color_tags.py). A PNG also carries
cICP (ITU-T H.273 codes: primaries, transfer, matrix 0 for RGB, full range), which the
PNG third edition ranks above iCCP.
"""

from __future__ import annotations

import struct
import zlib
from functools import cache
from pathlib import Path

ICC_DIR = Path(__file__).with_name("icc")
# H.273: colour primaries 12 (SMPTE EG 432-1, P3 with D65) and 9 (BT.2020); transfer 13
# (IEC 61966-2-1, sRGB's curve) and 1 (BT.709's, which Rec. 2020 uses).
CICP = {"display-p3": (12, 13), "rec2020": (9, 1)}
PROFILE_NAMES = {"display-p3": b"Display P3", "rec2020": b"Rec. 2020"}


@cache
def icc_profile(space: str) -> bytes | None:
    """The ICC profile of ``space``; None for sRGB (PNG's sRGB chunk says it)."""
    if space == "srgb":
        return None
    return (ICC_DIR / f"{space}.icc").read_bytes()


def png_chunks(space: str) -> list[tuple[bytes, bytes]]:
    """(type, payload) of the PNG chunks that tag ``space``, in file order."""
    if space == "srgb":
        return [(b"sRGB", b"\x00")]  # perceptual intent: the pixels are sRGB-encoded
    primaries, transfer = CICP[space]
    profile = icc_profile(space)
    assert profile is not None
    return [(b"cICP", struct.pack(">BBBB", primaries, transfer, 0, 1)),
            (b"iCCP", PROFILE_NAMES[space] + b"\x00\x00" + zlib.compress(profile))]
