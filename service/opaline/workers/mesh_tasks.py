"""Worker tasks for users' meshes: check an upload (parse it, validate it, summarise it).

Parsing runs here, in a render worker process, never in the HTTP process: a
malformed file is refused with ``MeshError`` (the reply kind ``invalid``, a
422 with the parser's reason), and a parser that crashes takes only a worker
down, which the pool replaces. A check has its own time limit, far under the
render watchdog's (a file that takes longer is refused as one this service
cannot read), and costs admission its predicted time (``admission.check_cost_s``).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any

from opaline.scene.meshfile import load_mesh_file
from opaline.workers.admission import CHECK_LABEL, CHECK_TIME_LIMIT_S
from opaline.workers.tasks import StopCheck

__all__ = ["CHECK_LABEL", "MeshCheckTask"]


@dataclass(frozen=True)
class MeshCheckTask:
    """Load a stored mesh as a render would; answer its summary as JSON."""

    path: str
    max_triangles: int
    label: str = CHECK_LABEL
    time_limit_s: float = CHECK_TIME_LIMIT_S

    def run(self, renderer: Any, should_stop: StopCheck) -> bytes:
        _, summary = load_mesh_file(self.path, max_triangles=self.max_triangles)
        return json.dumps(summary).encode()

    def units(self) -> tuple[str, float, int]:
        """The file's size in bytes: admission's model of a check (``CostModel.predict``)."""
        try:
            size = os.path.getsize(self.path)
        except OSError:
            size = 0
        return CHECK_LABEL, float(size), 0
