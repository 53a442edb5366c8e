"""A Radiance header's size is read as OpenCV's decoder reads it, or the file is refused.

The size is checked before OpenCV decodes the file; if the two read a header differently
the check bounds nothing. A stricter scan of the first 64 KiB missed a size line with two
spaces and one after 84 KiB of comments, and OpenCV then decoded 8192 × 16384 texels
(4 GB in a worker). Here every header, written by hand or by hypothesis from the parts
that trip readers (lines of 127 and 128 bytes, NULs, blank lines, other orientations,
white space of every kind), is read both ways: where ours gives a size, OpenCV's image
has that size.
"""

from __future__ import annotations

import io

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from opaline.scene import environment_files
from opaline.scene.environment_files import EnvironmentMapError, radiance_size

cv2 = pytest.importorskip("cv2")

FORMAT = b"FORMAT=32-bit_rle_rgbe\n"
SIZE = b"-Y 4 +X 8\n"
PIXELS = bytes([128, 64, 32, 129]) * 4 * 8  # flat RGBE: 4 rows of 8, what SIZE declares


def read_both(tmp_path, header: bytes) -> tuple[tuple[int, int] | None, tuple[int, ...] | None]:
    path = tmp_path / "map.hdr"
    path.write_bytes(header + PIXELS)
    try:
        ours = radiance_size(io.BytesIO(header + PIXELS))
    except ValueError:
        ours = None
    try:
        decoded = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except cv2.error:
        decoded = None
    return ours, None if decoded is None else decoded.shape[:2]


@pytest.mark.parametrize("header", [
    b"#?RADIANCE\n" + FORMAT + b"\n" + SIZE,
    b"#?RGBE\n# written by a tool\nEXPOSURE=1.0\nGAMMA=1\n" + FORMAT + b"\n" + SIZE,
    b"#?RADIANCE\n" + FORMAT + b"\n-Y  4  +X  8\n",  # the spacing a scan missed
    b"#?RADIANCE\n" + FORMAT + b"\n-Y4+X8\n",
    b"#?RADIANCE\n" + FORMAT + b"\n-Y 004 +X +8 and more\n",
    b"#?RADIANCE\n" + b"#" * 127 + FORMAT + b"\n" + SIZE,  # FORMAT is fgets' second piece
])
def test_headers_opencv_reads_are_read_alike(tmp_path, header):
    ours, theirs = read_both(tmp_path, header)
    assert ours == (8, 4) and theirs == (4, 8)


@pytest.mark.parametrize("header", [
    b"#?RADIANCE\n" + FORMAT + SIZE,  # no blank line
    b"#?RADIANCE\n" + FORMAT + b"\n+X 8 -Y 4\n",  # an orientation OpenCV does not read
    b"#?RADIANCE\n" + b"#" * 127 + b"\n" + FORMAT + b"\n" + SIZE,  # fgets: a blank piece
    b"#?RADIANCE\n" + b"FORMAT=32-bit_rle_rgbe\0\n" + b"\n" + SIZE,
    b"#?RADIANCE\n" + FORMAT + b"\n" + b"-Y" + b" " * 130 + b"4 +X 8\n",
    b"#?RADIANCE\n" + FORMAT + b"\n-Y 0 +X 8\n",
    b"#?RADIANCE\n" + FORMAT + b"\n-Y -4 +X 8\n",
    b"\x89PNG\r\n\x1a\n" + FORMAT + b"\n" + SIZE,
])
def test_headers_opencv_refuses_are_refused(tmp_path, header):
    ours, theirs = read_both(tmp_path, header)
    assert ours is None and theirs is None


PARTS = st.sampled_from([
    b"#?RADIANCE\n", b"#?RGBE\n", FORMAT, b"\n", b"\0", b"# c\n", b"#" * 126, b"#" * 127,
    b"#" * 128, b"EXPOSURE=2\n", b"FORMAT=32-bit_rle_rgbe", b"-Y", b"+X", b" ", b"\t",
    b"\r", b"\v", b"4", b"8", b"+", b"-", b"-Y 4 +X 8", SIZE,
])


@settings(max_examples=300, deadline=None)
@given(st.lists(PARTS, max_size=12))
def test_any_header_is_read_as_opencv_reads_it_or_refused(tmp_path_factory, parts):
    header = b"#?RADIANCE\n" + b"".join(parts)
    ours, theirs = read_both(tmp_path_factory.mktemp("hdr"), header)
    if ours is not None:
        assert theirs == (ours[1], ours[0])


@pytest.mark.parametrize("size_line", [b"-Y  8192  +X  16384\n", b"-Y 8192 +X\t16384\n"])
def test_a_map_over_the_limit_is_refused_however_its_size_is_spelt(tmp_path, size_line):
    (tmp_path / "big.hdr").write_bytes(b"#?RADIANCE\n" + FORMAT + b"\n" + size_line)
    with pytest.raises(EnvironmentMapError, match="16384 × 8192 texels is over"):
        environment_files.read_file(tmp_path / "big.hdr")


def test_a_header_longer_than_the_bound_is_refused_unread(tmp_path):
    comments = b"# padding\n" * (environment_files.MAX_RADIANCE_HEADER // 10 + 1)
    (tmp_path / "long.hdr").write_bytes(b"#?RADIANCE\n" + comments + FORMAT + b"\n" + SIZE
                                        + PIXELS)
    with pytest.raises(EnvironmentMapError, match="64 KiB"):
        environment_files.read_file(tmp_path / "long.hdr")


def test_a_file_cut_short_is_said_once_and_opencv_stays_quiet(tmp_path, capfd):
    """OpenCV logged its own "[ERROR:0@0.007] ... RGBE read error" to stderr, past the CLI's
    -q, before Opaline's one line; and the line said "not a Radiance .hdr image"."""
    (tmp_path / "cut.hdr").write_bytes(b"#?RADIANCE\n" + FORMAT + b"\n" + SIZE + PIXELS[:40])
    with pytest.raises(EnvironmentMapError, match="8 × 4.*cut short"):
        environment_files.read_file(tmp_path / "cut.hdr")
    assert capfd.readouterr().err == ""
