"""Worker tasks for users' meshes: check an upload (parse it, validate it, summarise it).

Parsing runs here, in a render worker process, never in the HTTP process: a
malformed file is refused with ``MeshError`` (the reply kind ``invalid``, a
422 with the parser's reason), and a parser that crashes takes only a worker
down, which the pool replaces.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from opaline.scene.meshfile import load_mesh_file
from opaline.workers.tasks import StopCheck

CHECK_LABEL = "mesh-check"


@dataclass(frozen=True)
class MeshCheckTask:
    """Load a stored mesh as a render would; answer its summary as JSON."""

    path: str
    max_triangles: int
    label: str = CHECK_LABEL

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        _, summary = load_mesh_file(self.path, max_triangles=self.max_triangles)
        return json.dumps(summary).encode()

    def units(self) -> tuple[str, float, int]:
        return CHECK_LABEL, 0.0, 0
