"""What an image answer adds about itself: the format chosen from Accept, and its timing.

``format=auto`` is replaced by the best format the client's Accept header allows
(the answer then varies by Accept); ``Server-Timing`` says whether the image came
from the cache or a worker, and how long the route took, so a client can tell the
service's own time from the network's.
"""

from __future__ import annotations

import time
from typing import Annotated

from fastapi import Depends, HTTPException, Request

from opaline.model.params import RenderRequest
from opaline.output.formats import negotiate


async def clock() -> float:
    """When the route started (a dependency, resolved before the body is parsed). Async, as
    every dependency on the image path: FastAPI runs a plain ``def`` one in its thread pool,
    a hand-off there and back (0.2-0.3 ms each on two busy cores, docs/speed.md)."""
    return time.perf_counter()


Started = Annotated[float, Depends(clock)]


def server_timing(started: float, source: str, render_s: float | None = None) -> str:
    """``total``: the route's own time; ``render``: waiting for the worker, on a miss."""
    parts = [f'{source};desc="{source}"']
    if render_s is not None:
        parts.append(f"render;dur={1e3 * render_s:.2f}")
    parts.append(f"total;dur={1e3 * (time.perf_counter() - started):.2f}")
    return ", ".join(parts)


def negotiated(params: RenderRequest, request: Request) -> RenderRequest:
    """``format=auto`` replaced by the format the Accept header prefers (406 if none)."""
    accept = request.headers.get("accept")
    fmt = negotiate(accept, alpha=bool(params.transparent))
    if fmt is None and negotiate(accept, alpha=False) is not None:
        raise HTTPException(406, "format=auto with transparent=true: the Accept header allows "
                            "only image/jpeg, which has no alpha channel; accept image/webp, "
                            "image/avif or image/png")
    if fmt is None:
        raise HTTPException(406, "format=auto: the Accept header allows none of image/webp, "
                            "image/avif, image/png, image/jpeg")
    return params.model_copy(update={"format": fmt})
