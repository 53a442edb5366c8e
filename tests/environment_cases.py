"""Environment maps for the extremes suite (issue 21; the materials' extremes are in
stability_cases.py): what a user's HDR file may hold, written as files into an
environments folder by ``write_environment``."""

from __future__ import annotations

import numpy as np

ENVIRONMENT_SIZE = (32, 64)
BRIGHT_TEXEL = 1e4  # the single bright texel's radiance


def _dim_sky() -> np.ndarray:
    rows = np.linspace(1.0, 0.2, ENVIRONMENT_SIZE[0], dtype=np.float32)
    return np.repeat(rows[:, None, None], ENVIRONMENT_SIZE[1], 1) * np.ones(3, np.float32)


def _range_1e5() -> np.ndarray:
    """A dim sky at 1 and a 3×3-texel sun at 1e5: the dynamic range of a real sunny map."""
    radiance = _dim_sky()
    radiance[6:9, 20:23] = 1e5
    return radiance


def _single_texel() -> np.ndarray:
    radiance = np.zeros((*ENVIRONMENT_SIZE, 3), np.float32)
    radiance[10, 40] = BRIGHT_TEXEL
    return radiance


def _broken() -> np.ndarray:
    """A sky with NaN, ±Inf, negative and float32-maximum texels, as a broken render or a
    badly merged bracket leaves them."""
    radiance = _dim_sky()
    radiance[3, 3:9] = np.nan
    radiance[5, 10:14] = np.inf
    radiance[7, 30:33] = -np.inf
    radiance[12, 40:50] = -5.0
    radiance[20, 5] = (np.nan, 1.0, np.inf)
    radiance[9, 50:52] = np.finfo(np.float32).max
    return radiance


# name -> (suffix, radiance): each written to a file of the environments folder.
ENVIRONMENT_MAPS = {
    "range-1e5": (".exr", _range_1e5),
    "black": (".exr", lambda: np.zeros((*ENVIRONMENT_SIZE, 3), np.float32)),
    "single-texel": (".exr", _single_texel),
    "nan-inf": (".exr", _broken),
    # Radiance RGBE holds no NaN, but an exponent byte of 255 is ~1e38.
    "rgbe-huge": (".hdr", lambda: np.where(_single_texel() > 0, 1e38, _dim_sky()).astype(
        np.float32)),
}


def write_environment(folder, name: str) -> str:
    """Writes ENVIRONMENT_MAPS[name] into ``folder``; the file's name."""
    suffix, make = ENVIRONMENT_MAPS[name]
    path = folder / f"stability-{name}{suffix}"
    radiance = make()
    if suffix == ".exr":
        import OpenEXR

        header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
        with OpenEXR.File(header, {"RGB": radiance}) as file:
            file.write(str(path))
    else:
        import cv2

        assert cv2.imwrite(str(path), np.ascontiguousarray(radiance[..., ::-1]))
    return path.name
