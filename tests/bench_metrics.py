"""bench/ modules for the tests, loaded from their files (bench/ is not a package):
metrics.py (PSNR, ΔE00, FLIP) for the tests that judge images against references, so the
tests and the benchmarks score with the same code, and any other by ``load_bench``."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

BENCH = Path(__file__).resolve().parents[1] / "bench"


def load_bench(name: str) -> ModuleType:
    """``bench/<name>.py`` as a module; bench/ is on the path while it runs, for its own
    imports of the modules beside it."""
    spec = importlib.util.spec_from_file_location(f"opaline_bench_{name}", BENCH / f"{name}.py")
    assert spec is not None and spec.loader is not None, f"bench/{name}.py"
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(BENCH))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(BENCH))
    return module


metrics = load_bench("metrics")
