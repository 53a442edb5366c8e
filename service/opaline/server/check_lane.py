"""The lane that checks uploaded meshes: a worker process of its own, beside the render
workers, so that a flood of uploads never queues in front of renders (and a render
backlog never delays an upload's answer).

A check parses a user's file (``workers.mesh_tasks.MeshCheckTask``) with the
same supervision as a render: its own time limit, a hard memory ceiling for the
parse (``scene/parse_memory.py``), a heartbeat, replacement if it dies or hangs,
and admission against the deadline. The worker holds no GL context
(``workers.factory.ParserOnly``): it costs one Python process, counted in
``settings.memory_budget_bytes``.
"""

from __future__ import annotations

from opaline.settings import Settings
from opaline.workers.factory import ParserFactory
from opaline.workers.pool import WorkerPool

CHECK_WORKERS = 1


def check_lane(settings: Settings) -> WorkerPool:
    """The pool of mesh-check workers; started and stopped with the render workers."""
    return WorkerPool(ParserFactory(), workers=CHECK_WORKERS, queue_size=settings.queue_size,
                      deadline_s=settings.deadline_s,
                      render_timeout_s=settings.render_timeout_s,
                      max_renders=settings.worker_max_renders,
                      max_rss_bytes=settings.worker_max_rss_mb * 1024 * 1024, lp_threads=1)
