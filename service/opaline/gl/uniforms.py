"""Setting a program's uniforms from a dict of values (gl/material_program.py makes the
material's)."""

from __future__ import annotations

import moderngl
import numpy as np


def apply(program: moderngl.Program, values: dict[str, object]) -> None:
    """Set the uniforms the program has; the compiler drops unused ones per variant."""
    for name, value in values.items():
        member = program.get(name, None)
        if member is None:
            continue
        if isinstance(value, np.ndarray):
            member.write(value.astype("f4").tobytes())
        elif isinstance(value, list) and member.array_length == 1:
            member.value = value[0]  # moderngl treats a one-element array as a scalar
        else:
            member.value = value
