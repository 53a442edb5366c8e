"""WebP, AVIF and JPEG through Pillow, and choosing a format from an Accept header.

Settings were chosen by measuring bytes and time per preset (docs/speed.md):
the fastest encoder setting of each codec whose output is visually clean at
256². Pillow's encoders are deterministic for a given build, so the same
pixels give the same bytes.
"""

from __future__ import annotations

import io

import numpy as np

# Lossy formats: smaller, and exact pixel values are not kept.
LOSSY = frozenset({"webp", "avif", "jpeg"})
HAS_ALPHA = frozenset({"png", "png16", "webp", "webp-lossless", "avif", "npy"})
# Pillow save arguments per format.
SETTINGS: dict[str, tuple[str, dict[str, int | bool]]] = {
    "webp": ("WEBP", {"quality": 85, "method": 0}),
    "webp-lossless": ("WEBP", {"lossless": True, "quality": 0, "method": 0, "exact": True}),
    "avif": ("AVIF", {"quality": 75, "speed": 10}),
    "jpeg": ("JPEG", {"quality": 90}),
}
# format=auto: what each media type maps to, in the service's order of preference
# when the client weighs several equally: small and fast first, PNG as the lossless
# fallback for clients that name none of them.
NEGOTIABLE = (("image/webp", "webp"), ("image/avif", "avif"), ("image/png", "png"),
              ("image/jpeg", "jpeg"))
DEFAULT = "png"


def encode_pillow(pixels: np.ndarray, fmt: str, icc: bytes | None = None) -> bytes:
    """``pixels`` in ``fmt``, with the ICC profile ``icc`` of their colour space (none:
    sRGB, each format's default)."""
    from PIL import Image  # only these formats need Pillow: the PNG path stays light

    name, options = SETTINGS[fmt]
    image = Image.fromarray(np.ascontiguousarray(pixels), "RGBA" if pixels.shape[2] == 4 else "RGB")
    out = io.BytesIO()
    image.save(out, format=name, **options, **({"icc_profile": icc} if icc else {}))
    return out.getvalue()


def _weights(accept: str) -> list[tuple[str, float]]:
    ranges = []
    for part in accept.split(","):
        fields = [f.strip() for f in part.split(";")]
        if not fields[0]:
            continue
        q = 1.0
        for param in fields[1:]:
            key, _, value = param.partition("=")
            if key.strip().lower() == "q":
                try:
                    q = min(max(float(value), 0.0), 1.0)
                except ValueError:
                    q = 0.0
        ranges.append((fields[0].lower(), q))
    return ranges


def _quality(media_type: str, ranges: list[tuple[str, float]]) -> float | None:
    """The q the client gives ``media_type``: from its most specific matching range."""
    kind = media_type.split("/")[0]
    best: tuple[int, float] | None = None
    for pattern, q in ranges:
        if pattern == media_type:
            rank = 2
        elif pattern == f"{kind}/*":
            rank = 1
        elif pattern == "*/*":
            rank = 0
        else:
            continue
        if best is None or rank > best[0]:
            best = (rank, q)
    return None if best is None else best[1]


def negotiate(accept: str | None, alpha: bool) -> str | None:
    """The format for ``format=auto``: the highest q the client gives any image type we
    make (JPEG only when no alpha is needed), ties in ``NEGOTIABLE`` order; a wildcard
    alone gives PNG; None when the client accepts none of them (406)."""
    if not accept or not accept.strip():
        return DEFAULT
    ranges = _weights(accept)
    explicit = {pattern for pattern, _ in ranges}
    best: tuple[float, int, str] | None = None
    for order, (media_type, fmt) in enumerate(NEGOTIABLE):
        if alpha and fmt not in HAS_ALPHA:
            continue
        q = _quality(media_type, ranges)
        if not q:
            continue
        # Through a wildcard only, a type competes as the default would: PNG first.
        rank = order if media_type in explicit else len(NEGOTIABLE) + (fmt != DEFAULT)
        if best is None or (q, -rank) > (best[0], -best[1]):
            best = (q, rank, fmt)
    return None if best is None else best[2]
