"""A user's environment file: read, checked, cleaned and brought to a size lighting can use.

Radiance ``.hdr`` is read through OpenCV, OpenEXR ``.exr`` through the OpenEXR package,
both imported only when a file is asked for, in the worker processes. What comes out is
linear RGB float32 in the equirectangular convention of ``mediancut``:

* **Bounded before decoding.** The header's size is read first, and a map over
  ``MAX_FILE_PIXELS`` is refused, naming its size and the limit: an 8192 × 4096 HDRI
  decodes to 400 MB; a 16k one would be 1.6 GB, and an 8k map once took a worker 8.8 GB
  and 28 s (its harmonics were taken in float64 at full size).
* **Cleaned in place.** NaN, infinite and negative texels become 0 and radiance is
  clamped to ``MAX_RADIANCE`` (logged), without a float64 copy of the map.
* **Fitted** (``fit``): wider than ``MAX_WIDTH`` or taller than half that, a map is
  averaged down (each texel the mean of the ones it covers); narrower than
  ``MIN_WIDTH`` or shorter than half that, each texel is repeated, which keeps every
  direction's radiance. A uniform map then lights alike at any size: at 1 × 1 its
  irradiance's constant term was 4.93 where π is right, one row's texels all taken at
  the equator's solid angle.
* **Named by content** (``digests.known_file_digest``, in ``pipeline.prepare``), so a file
  replaced under the same name is a new scene: keys and revs follow the bytes, and the
  workers' caches the file's size and time (``environments.map_identity``).
"""

from __future__ import annotations

import logging
import math
import re
import threading
from pathlib import Path
from typing import BinaryIO

import numpy as np

# The most radiance a file's texel keeps. Far above any real scene in relative units (a
# sun is ~1e5 times its sky); below it every range at its end (environment_intensity
# 1000, ks 100, the three-lobe mixture's weight 3, exposure 1000: 3e8 per unit radiance)
# keeps fp32 finite through the ACES tone map, whose x² overflows above 1.8e19.
MAX_RADIANCE = 1e10
MAX_FILE_PIXELS = 8192 * 4096  # an 8k HDRI: 400 MB as float32 RGB
MAX_WIDTH = 2048  # 0.18° a texel: finer than a 256² preview's pixel at 40°
MIN_WIDTH = 128
# sscanf's "-Y %d +X %d": a space matches any run of white space, %d skips it too.
RADIANCE_SIZE = re.compile(rb"-Y\s*([-+]?\d+)\s*\+X\s*([-+]?\d+)")
RADIANCE_SIGNATURES = (b"#?RGBE", b"#?RADIANCE")
RADIANCE_FORMAT = b"FORMAT=32-bit_rle_rgbe\n"
MAX_RADIANCE_HEADER = 1 << 16

log = logging.getLogger(__name__)
_QUIET_OPENCV = threading.Lock()


class EnvironmentMapError(ValueError):
    """An environment that is not known or cannot be read; the message says which."""


def read_file(path: Path) -> np.ndarray:
    """Linear RGB float32 (H, W, 3) from a Radiance .hdr or an OpenEXR file, cleaned."""
    suffix = path.suffix.lower()
    try:
        image = _read_exr(path) if suffix == ".exr" else _read_radiance(path)
    except ImportError as exc:
        raise EnvironmentMapError(f"environment {path.name}: reading {suffix} files needs "
                                   f"{exc.name}, a dependency of opaline: reinstall it") from None
    except (OSError, ValueError, KeyError, RuntimeError) as exc:
        # The folder is the server's business: the message names the file, not its path.
        reason = str(exc).replace(str(path), path.name)
        raise EnvironmentMapError(f"environment {path.name}: cannot read: {reason}") from None
    if image.ndim != 3 or image.shape[2] < 3:
        raise EnvironmentMapError(f"environment {path.name}: expected finite RGB, got "
                                   f"shape {image.shape}")
    return sanitised(path.name, image[..., :3])


def _check_size(width: int, height: int) -> None:
    if width <= 0 or height <= 0:
        raise ValueError(f"{width} × {height} texels: no image")
    if width * height > MAX_FILE_PIXELS:
        raise ValueError(f"{width} × {height} texels is over the {MAX_FILE_PIXELS:,} this "
                         f"service reads (8192 × 4096): scale it down ({MAX_WIDTH} × "
                         f"{MAX_WIDTH // 2} is what lighting uses)")


def _read_exr(path: Path) -> np.ndarray:
    import OpenEXR

    with OpenEXR.File(str(path), header_only=True) as header:
        # Every part is decoded below, and a map is one image: a second part of 16384²
        # behind a small first one was read whole (600 KB of file, 530 MB in the worker).
        if len(header.parts) != 1:
            raise ValueError(f"{len(header.parts)} parts: an environment map is one image, "
                             "a single-part file")
        (x0, y0), (x1, y1) = header.header()["dataWindow"]
        _check_size(int(x1) - int(x0) + 1, int(y1) - int(y0) + 1)
    with OpenEXR.File(str(path)) as exr:
        channels = exr.channels()
        for group in ("RGB", "RGBA"):  # RGBA is what most tools write: its alpha is unread
            if group in channels:
                return np.asarray(channels[group].pixels, dtype=np.float32)
        if all(c in channels for c in "RGB"):
            return np.stack([np.asarray(channels[c].pixels, dtype=np.float32)
                             for c in "RGB"], -1)
        raise ValueError(f"no R, G and B channels (it has {', '.join(channels)})")


def _read_radiance(path: Path) -> np.ndarray:
    with open(path, "rb") as stream:
        width, height = radiance_size(stream)
    _check_size(width, height)
    import cv2  # opencv-python-headless: reads Radiance RGBE as float32 BGR

    # OpenCV logs a file it cannot read to stderr itself, past the CLI's -q: the error
    # raised here says it once, so its log is silenced for the read (and restored; the
    # level is the process's, so one read at a time: the Python API's threads).
    logging_ = cv2.utils.logging
    with _QUIET_OPENCV:
        level = logging_.getLogLevel()
        logging_.setLogLevel(logging_.LOG_LEVEL_SILENT)
        try:
            decoded = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        except cv2.error as exc:  # e.g. a header declaring more pixels than OpenCV allows
            raise ValueError(f"OpenCV refused it: {exc.err} ({exc.func})") from None
        finally:
            logging_.setLogLevel(level)
    if decoded is None or decoded.shape[:2] != (height, width):
        raise ValueError(f"its header reads ({width} × {height}) but its pixels do not: "
                         "the file is cut short or damaged")
    image: np.ndarray = np.asarray(decoded, dtype=np.float32)[..., 2::-1]
    return image


def radiance_size(stream: BinaryIO) -> tuple[int, int]:
    """(width, height) of a Radiance header, read as OpenCV's reader reads it (rgbe.cpp,
    ``RGBE_ReadHeader``): lines as ``fgets`` gives them into 128 bytes, each a C string, up
    to ``FORMAT=32-bit_rle_rgbe``, a blank line, then ``sscanf("-Y %d +X %d")``. Anything
    that reader might take differently is refused (a ValueError) before it decodes: a
    size line with two spaces, or after 64 KiB of comments, passed a stricter scan that
    found none, and an 8192 × 16384 map was decoded (4 GB in the worker)."""
    signature = stream.read(len(RADIANCE_SIGNATURES[1]))
    if not signature.startswith(RADIANCE_SIGNATURES):  # OpenCV read a PNG named .hdr
        raise ValueError("not a Radiance .hdr image (it does not begin with '#?RADIANCE' "
                         "or '#?RGBE')")
    stream.seek(0)
    line = _c_line(stream)
    while line != RADIANCE_FORMAT:
        if line[:1] in (b"", b"\n") or stream.tell() > MAX_RADIANCE_HEADER:
            raise ValueError("no FORMAT=32-bit_rle_rgbe line in its first "
                             f"{MAX_RADIANCE_HEADER // 1024} KiB of header")
        line = _c_line(stream)
    if _c_line(stream) != b"\n":
        raise ValueError("no blank line after its FORMAT line")
    found = RADIANCE_SIZE.match(_c_line(stream))
    if not found or int(found.group(1)) <= 0 or int(found.group(2)) <= 0:
        raise ValueError("no '-Y height +X width' line after its FORMAT line and a blank one "
                         "(other orientations are not read)")
    return int(found.group(2)), int(found.group(1))


def _c_line(stream: BinaryIO) -> bytes:
    """What ``fgets(buf, 128, f)`` leaves in ``buf``, up to its first NUL."""
    return stream.readline(127).split(b"\0", 1)[0]


def sanitised(name: str, radiance: np.ndarray) -> np.ndarray:
    """NaN, ±Inf and negative texels as 0 (a broken pixel is no light: an Inf taken as the
    maximum would put a sun where none is), the rest clamped to ``MAX_RADIANCE``; in a
    float32 copy of its own, changed in place."""
    clean = np.array(radiance, dtype=np.float32, order="C")
    broken = ~np.isfinite(clean)
    broken_count = int(np.count_nonzero(broken))
    clean[broken] = 0.0
    del broken
    broken_count += int(np.count_nonzero(clean < 0.0))
    np.maximum(clean, 0.0, out=clean)
    bright_count = int(np.count_nonzero(clean > MAX_RADIANCE))
    np.minimum(clean, MAX_RADIANCE, out=clean)
    if broken_count or bright_count:
        log.warning("environment %s: %d non-finite or negative values set to 0, %d above "
                    "%g clamped", name, broken_count, bright_count, MAX_RADIANCE)
    return clean


def fit(radiance: np.ndarray) -> np.ndarray:
    """The map within ``MIN_WIDTH`` … ``MAX_WIDTH`` texels wide and half that tall, each
    side on its own: averaged down, or each texel repeated up."""
    height, width = radiance.shape[:2]
    if width > MAX_WIDTH or height > MAX_WIDTH // 2:
        import cv2

        size = (min(width, MAX_WIDTH), min(height, MAX_WIDTH // 2))
        radiance = cv2.resize(radiance, size, interpolation=cv2.INTER_AREA)
        height, width = radiance.shape[:2]
    repeat_x = math.ceil(MIN_WIDTH / width) if width < MIN_WIDTH else 1
    repeat_y = math.ceil(MIN_WIDTH // 2 / height) if height < MIN_WIDTH // 2 else 1
    if repeat_x > 1 or repeat_y > 1:
        radiance = np.repeat(np.repeat(radiance, repeat_y, axis=0), repeat_x, axis=1)
    return np.ascontiguousarray(radiance, dtype=np.float32)
