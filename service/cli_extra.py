"""Sub-commands added by later stages (serve, batch, schema, bench, gallery)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    from . import gallery

    gallery.register(sub)
