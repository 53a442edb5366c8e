"""bench/metrics.py (PSNR, ΔE00, FLIP) for the tests that judge images against references:
one loader, so the tests and the benchmarks score with the same code."""

from __future__ import annotations

import importlib.util
from pathlib import Path


def _load():
    path = Path(__file__).resolve().parents[1] / "bench" / "metrics.py"
    spec = importlib.util.spec_from_file_location("opaline_bench_metrics", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


metrics = _load()
