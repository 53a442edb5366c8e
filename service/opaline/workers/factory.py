"""How a worker process makes its renderer: a picklable recipe, so that the parent never
imports moderngl or touches GL itself."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class RendererFactory:
    backend: str | None = None
    max_programs: int = 64
    scene_bytes: int = 128 * 1024 * 1024
    target_bytes: int = 256 * 1024 * 1024
    environments_dir: Path | None = None  # the user's environment maps (settings)
    environment_paths: bool = False  # maps named by a path too (local batches), not served

    def __call__(self) -> Any:
        from opaline.gl.buffers import RenderBudgets
        from opaline.gl.renderer import Renderer

        budgets = RenderBudgets(max_programs=self.max_programs, scene_bytes=self.scene_bytes,
                                target_bytes=self.target_bytes)
        return Renderer(self.backend, budgets=budgets, environments_dir=self.environments_dir,
                        environment_paths=self.environment_paths)


class ParserOnly:
    """What a mesh-check worker holds instead of a renderer: no GL context (a check parses
    a file and never draws), so the lane costs a Python process, not a context."""

    gl = None

    def release(self) -> None:
        pass


@dataclass(frozen=True)
class ParserFactory:
    """The recipe of the mesh-check lane's worker (``server/check_lane.py``)."""

    def __call__(self) -> ParserOnly:
        return ParserOnly()
