"""Sub-commands added by later stages (serve, batch, schema, bench, gallery)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    from . import gallery

    gallery.register(sub)
    from . import serve; serve.register(sub)  # noqa: E702, I001
    from . import batch, materials

    batch.register(sub)
    materials.register(sub)
