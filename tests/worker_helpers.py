"""Test-only worker tasks and renderer factories: module-level, so a spawned worker can
unpickle them (it imports this module by name from the tests folder)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from opaline.gl.renderer import Renderer
from opaline.gl.shaders import ShaderError

WAIT = 20.0


@dataclass(frozen=True)
class GateTask:
    """Keeps its worker busy until ``opened`` exists (or the pool asks it to stop)."""

    folder: str
    label: str = "gate"

    @property
    def entered(self) -> Path:
        return Path(self.folder) / "entered"

    @property
    def opened(self) -> Path:
        return Path(self.folder) / "opened"

    def run(self, renderer, should_stop) -> bytes:
        self.entered.touch()
        end = time.monotonic() + WAIT
        while not self.opened.exists() and time.monotonic() < end:
            if should_stop():
                from opaline.gl.renderer import Cancelled

                raise Cancelled("gate stopped")
            time.sleep(0.01)
        return b"gate"

    def units(self) -> tuple[str, float, int]:
        return "gate", 0.0, 0

    def wait_entered(self) -> None:
        end = time.monotonic() + WAIT
        while not self.entered.exists():
            assert time.monotonic() < end, "the gate task never started"
            time.sleep(0.01)

    def open(self) -> None:
        self.opened.touch()


@dataclass(frozen=True)
class EchoTask:
    """Answers its payload at once: a render that costs nothing."""

    payload: bytes = b"echo"
    label: str = "echo"

    def run(self, renderer, should_stop) -> bytes:
        return self.payload

    def units(self) -> tuple[str, float, int]:
        return "echo", 0.0, 0


@dataclass(frozen=True)
class CrashTask:
    """Ends the worker process mid-job, as the OOM killer or a driver crash would."""

    label: str = "crash"

    def run(self, renderer, should_stop) -> bytes:
        import os

        os._exit(3)

    def units(self) -> tuple[str, float, int]:
        return "crash", 0.0, 0


@dataclass(frozen=True)
class SlowCheckTask:
    """Sleeps past its own time limit, as a mesh check of a slow file would."""

    seconds: float = 5.0
    time_limit_s: float = 0.5
    label: str = "mesh-check"

    def run(self, renderer, should_stop) -> bytes:
        time.sleep(self.seconds)
        return b"{}"

    def units(self) -> tuple[str, float, int]:
        return "mesh-check", 0.0, 0


@dataclass(frozen=True)
class SpinTask:
    """Holds the GIL for ``seconds`` in one C call (as a long GL draw can), burning CPU."""

    seconds: float = 3.0
    label: str = "spin"

    def run(self, renderer, should_stop) -> bytes:
        import re

        # Catastrophic backtracking: one re.match call, GIL held throughout.
        end = time.monotonic() + self.seconds
        n = 20
        while time.monotonic() < end:
            re.match(r"(a+)+$", "a" * n + "b")
            n += 1
        return b"spun"

    def units(self) -> tuple[str, float, int]:
        return "spin", 0.0, 0


def no_gl():
    raise RuntimeError("no EGL device")


class BrokenRenderer(Renderer):
    def render(self, job, preset=None, all_features=False, should_stop=None):
        raise ShaderError("surface.glsl:12: error: SECRET-COMPILE-LOG")


class LostContextRenderer(Renderer):
    """Draws nothing: every render raises as a lost GL context does."""

    def render(self, job, preset=None, all_features=False, should_stop=None):
        raise RuntimeError("GL_CONTEXT_LOST")


def null_renderer():
    """A renderer without GL, for pool tests that never draw."""
    return NullRenderer()


class NullRenderer:
    def release(self) -> None:
        pass
