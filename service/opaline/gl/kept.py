"""What a renderer keeps between renders, each under its budget (a mixin of Renderer).

Framebuffers per image size and uploaded scenes are LRUs bounded by count and
bytes (``RenderBudgets``); a shader program leaving the program cache takes the
vertex arrays made for it along (GL reuses the names of released objects).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import moderngl

from opaline.gl.buffers import RenderBudgets, SceneGPU, Targets
from opaline.lru import BudgetLRU
from opaline.model.presets import Preset


class Kept:
    ctx: moderngl.Context
    budgets: RenderBudgets
    programs: Any
    _targets: BudgetLRU[tuple[int, int], Targets]
    _scenes: BudgetLRU[str, SceneGPU]
    _empty_vao: dict[int, moderngl.VertexArray]

    def targets(self, size: tuple[int, int]) -> Targets:
        return _kept(self._targets, size, lambda: Targets(self.ctx, size),
                     f"{size[0]}×{size[1]} targets exceed", self.budgets.target_bytes)

    def scene(self, preset: Preset) -> SceneGPU:
        return _kept(self._scenes, preset.scene_key(), lambda: SceneGPU(self.ctx, preset),
                     f"scene {preset.name} exceeds", self.budgets.scene_bytes)

    def cache_stats(self) -> dict[str, int]:
        """Sizes and evictions of what this renderer keeps (reported by render workers)."""
        return {"programs": len(self.programs), "program_evictions": self.programs.evictions,
                "scenes": len(self._scenes), "scene_bytes": self._scenes.size_bytes,
                "scene_evictions": self._scenes.evictions, "targets": len(self._targets),
                "target_bytes": self._targets.size_bytes,
                "target_evictions": self._targets.evictions}

    def _forget_program(self, program: moderngl.Program) -> None:
        for scene in self._scenes.values():
            scene.drop_vao(program.glo)
        vao = self._empty_vao.pop(program.glo, None)
        if vao is not None:
            vao.release()


def _kept(kept: BudgetLRU[Any, Any], key: Any, make: Callable[[], Any], what: str,
          budget: int) -> Any:
    """``kept[key]``, made and kept if missing; released and refused if it alone is over
    the budget."""
    found = kept.get(key)
    if found is None:
        found = make()
        if not kept.put(key, found, found.nbytes):
            found.release()
            raise ValueError(f"{what} the renderer's budget of {budget} bytes")
    return found
