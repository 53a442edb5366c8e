"""What a renderer owns in its GL context and keeps between renders, each under its budget.

Framebuffers per image size and uploaded scenes are LRUs bounded by count and
bytes (``RenderBudgets``); a shader program leaving the program cache takes the
vertex arrays made for it along (GL reuses the names of released objects). The
draws (surface, resolve, probes) are handed this object; none of them owns GL state.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Protocol, TypeVar

import moderngl
import numpy as np

from opaline.gl.buffers import RenderBudgets, SceneGPU, Targets
from opaline.gl.context import GLContext
from opaline.gl.shaders import ProgramCache
from opaline.lru import BudgetLRU
from opaline.model.presets import Preset


class Resources:
    """The context, its targets, scenes, programs, full-screen VAOs and flat normal map."""

    def __init__(self, gl: GLContext, budgets: RenderBudgets) -> None:
        self.gl = gl
        self.ctx: moderngl.Context = gl.ctx
        self.budgets = budgets
        self.kept_targets: BudgetLRU[tuple[int, int], Targets] = BudgetLRU(
            budgets.max_target_sizes, budgets.target_bytes, release=Targets.release)
        self.kept_scenes: BudgetLRU[str, SceneGPU] = BudgetLRU(
            budgets.max_scenes, budgets.scene_bytes, release=SceneGPU.release)
        self._empty_vao: dict[int, moderngl.VertexArray] = {}
        self._flat_normal: moderngl.Texture | None = None
        self.programs = ProgramCache(self.ctx, budgets.max_programs, self._forget_program)

    def targets(self, size: tuple[int, int]) -> Targets:
        return _kept(self.kept_targets, size, lambda: Targets(self.ctx, size),
                     f"{size[0]}×{size[1]} targets exceed", self.budgets.target_bytes)

    def scene(self, preset: Preset) -> SceneGPU:
        return _kept(self.kept_scenes, preset.scene_key(), lambda: SceneGPU(self.ctx, preset),
                     f"scene {preset.name} exceeds", self.budgets.scene_bytes)

    def fullscreen(self, program: moderngl.Program) -> None:
        """One triangle over the viewport, through a buffer-less VAO kept per program."""
        vao = self._empty_vao.get(program.glo)
        if vao is None:
            vao = self._empty_vao[program.glo] = self.ctx.vertex_array(program, [])
        vao.render(moderngl.TRIANGLES, vertices=3)

    def flat_normal_map(self) -> moderngl.Texture:
        """A 1×1 map of the unperturbed normal, for the all-features baseline."""
        if self._flat_normal is None:
            data = np.array([0.0, 0.0, 1.0], dtype="f4").tobytes()
            self._flat_normal = self.ctx.texture((1, 1), 3, data, dtype="f4")
        return self._flat_normal

    def cache_stats(self) -> dict[str, int]:
        """Sizes and evictions of what this renderer keeps (reported by render workers)."""
        return {"programs": len(self.programs), "program_evictions": self.programs.evictions,
                "scenes": len(self.kept_scenes), "scene_bytes": self.kept_scenes.size_bytes,
                "scene_evictions": self.kept_scenes.evictions,
                "targets": len(self.kept_targets),
                "target_bytes": self.kept_targets.size_bytes,
                "target_evictions": self.kept_targets.evictions}

    def _forget_program(self, program: moderngl.Program) -> None:
        for scene in self.kept_scenes.values():
            scene.drop_vao(program.glo)
        vao = self._empty_vao.pop(program.glo, None)
        if vao is not None:
            vao.release()

    def release(self) -> None:
        """Everything made in the context (the caller makes it current and releases it)."""
        for vao in self._empty_vao.values():
            vao.release()
        self._empty_vao.clear()
        self.kept_scenes.clear()
        self.kept_targets.clear()
        if self._flat_normal is not None:
            self._flat_normal.release()
        self.programs.release()


class Kept(Protocol):
    """What a renderer keeps under a byte budget: targets and scenes."""

    @property
    def nbytes(self) -> int: ...

    def release(self) -> None: ...


KeyT = TypeVar("KeyT", bound=Hashable)
KeptT = TypeVar("KeptT", bound=Kept)


def _kept(kept: BudgetLRU[KeyT, KeptT], key: KeyT, make: Callable[[], KeptT], what: str,
          budget: int) -> KeptT:
    """``kept[key]``, made and kept if missing; released and refused if it alone is over
    the budget."""
    found = kept.get(key)
    if found is None:
        found = make()
        if not kept.put(key, found, found.nbytes):
            found.release()
            raise ValueError(f"{what} the renderer's budget of {budget} bytes")
    return found
