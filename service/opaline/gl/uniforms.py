"""Setting a program's uniforms from a dict of values (gl/material_program.py makes the
material's)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import moderngl
import numpy as np

Vector = tuple[float, ...]
# A scalar, a vector, an array of either, or a matrix (an ndarray, written as f4 bytes).
# Sequences, not lists: a list of pairs (list[tuple[float, float]]) is one of vectors.
UniformValue = float | Vector | Sequence[float] | Sequence[Vector] | np.ndarray
Uniforms = dict[str, UniformValue]


def apply(program: moderngl.Program, values: Mapping[str, UniformValue]) -> None:
    """Set the uniforms the program has; the compiler drops unused ones per variant."""
    for name, value in values.items():
        member = uniform(program, name)
        if member is None:
            continue
        if isinstance(value, np.ndarray):
            member.write(value.astype("f4").tobytes())
        elif isinstance(value, list) and member.array_length == 1:
            member.value = value[0]  # moderngl treats a one-element array as a scalar
        else:
            member.value = value


def uniform(program: moderngl.Program, name: str) -> moderngl.Uniform | None:
    """The program's uniform ``name``, or None where the variant has none by that name."""
    member = program.get(name, None)
    if member is None or isinstance(member, moderngl.Uniform):
        return member
    # A program's members share one namespace with its attributes, varyings and blocks.
    raise TypeError(f"{name} is a {type(member).__name__} of the program, not a uniform")
