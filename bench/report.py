"""Where every benchmark leaves its figures: bench/results/NAME.json, and beside it
NAME.md, each written whole or not at all (a run stopped half-way keeps the last)."""

from __future__ import annotations

import json
from pathlib import Path

from opaline.output.files import write_atomic

RESULTS = Path(__file__).resolve().parent / "results"


def save(name: str, data: object, table: str | None = None, show: bool = True) -> None:
    """``data`` as NAME.json; ``table`` (markdown) as NAME.md, printed when ``show``."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_atomic(RESULTS / f"{name}.json", (json.dumps(data, indent=2) + "\n").encode())
    if table is not None:
        write_atomic(RESULTS / f"{name}.md", table.encode())
        if show:
            print(table.rstrip("\n"))
