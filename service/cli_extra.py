"""Sub-commands that live in their own modules (gallery, serve, batch, schema)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    from . import batch, gallery, materials, serve

    for module in (gallery, serve, batch, materials):
        module.register(sub)
