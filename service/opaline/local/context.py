"""What a request is prepared against in this process (CLI, Python API, local batches):
mesh and environment files on this machine and the ``OPALINE_*`` settings. No GL is loaded here."""

from __future__ import annotations

from opaline.model.meshes import file_mesh_preset
from opaline.model.params import RenderRequest
from opaline.model.presets import Preset
from opaline.pipeline.limits import Limits
from opaline.pipeline.prepare import Context
from opaline.settings import setting


def file_meshes(request: RenderRequest, preset: Preset) -> Preset:
    """A request's ``mesh`` is a file on this machine."""
    return file_mesh_preset(preset, request, setting("mesh_max_triangles"))


def local_context(cost_budget: int | None) -> Context:
    """Requests prepared in this process: files for meshes and environments, the
    OPALINE_* settings."""
    return Context(Limits(cost_budget), file_meshes, setting("environments_dir"),
                   environment_paths=True)
