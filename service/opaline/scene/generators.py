"""Argument checks and dispatch shared by the procedural generators.

Geometry and normal-map generators are named in preset files, which are text
from outside, so every failure is a ValueError naming the generator and the
argument; the preset loader passes it on verbatim.
"""

from __future__ import annotations

import inspect
import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")


def _is_number(value: Any, kind: type) -> bool:
    """A number of ``kind`` that is not a bool (True is an Integral to Python, not to us).

    Not a type guard: the checks below compare ``value`` as given, whatever number it is."""
    return not isinstance(value, bool) and isinstance(value, kind)


def integer(name: str, value: Any, lo: int, hi: int) -> int:
    if not _is_number(value, numbers.Integral):
        raise ValueError(f"argument '{name}' must be an integer from {lo} to {hi}, got {value!r}")
    if not lo <= value <= hi:
        raise ValueError(f"argument '{name}' must be an integer from {lo} to {hi}, got {value}")
    return int(value)


def real(name: str, value: Any, lo: float | None = None, hi: float | None = None) -> float:
    bounded = lo is not None and hi is not None
    wanted = f"a number from {lo} to {hi}" if bounded else "a finite number"
    if not _is_number(value, numbers.Real) or not math.isfinite(value):
        raise ValueError(f"argument '{name}' must be {wanted}, got {value!r}")
    if lo is not None and hi is not None and not lo <= value <= hi:
        raise ValueError(f"argument '{name}' must be {wanted}, got {value}")
    return float(value)


def positive(name: str, value: Any) -> float:
    number = real(name, value)
    if number <= 0.0:
        raise ValueError(f"argument '{name}' must be > 0, got {number}")
    return number


def sequence(name: str, value: Any, length: int) -> Sequence[Any] | np.ndarray:
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise ValueError(f"argument '{name}' must be a sequence of {length} numbers, got {value!r}")
    if len(value) != length:
        raise ValueError(f"argument '{name}' must have {length} entries, got {len(value)}")
    return value


def call(family: str, kinds: Mapping[str, Callable[..., T]], kind: str, args: dict[str, Any]) -> T:
    """Call ``kinds[kind](**args)``, refusing unknown kinds and unknown or missing arguments."""
    factory = kinds.get(kind)
    if factory is None:
        raise ValueError(f"unknown {family} {kind!r} (known: {', '.join(kinds)})")
    parameters = inspect.signature(factory).parameters
    for name in args:
        if name not in parameters:
            known = f"known: {', '.join(parameters)}" if parameters else "it takes none"
            raise ValueError(f"{family} {kind!r}: unknown argument {name!r} ({known})")
    missing = [
        name
        for name, p in parameters.items()
        if p.default is inspect.Parameter.empty and name not in args
    ]
    if missing:
        raise ValueError(f"{family} {kind!r}: missing argument {missing[0]!r}")
    try:
        return factory(**args)
    except ValueError as error:
        raise ValueError(f"{family} {kind!r}: {error}") from None
