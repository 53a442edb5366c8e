"""The first stage of every request: from fields to a job that is ready to render.

``prepare`` finds the scene (the preset, drawing the request's mesh if it names
one), checks the environment's name, resolves the request once, checks the
deployment's limits and names the result: its cache key and, on demand, its
canonical URL. Nothing here touches GL, so the HTTP process prepares requests
itself and hands only the prepared job to a worker.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from opaline.digests import known_file_digest
from opaline.errors import PublicError
from opaline.model.params import RenderRequest
from opaline.model.presets import Preset, get_preset
from opaline.model.request import Job, resolve
from opaline.pipeline.canonical import canonical_query, canonical_url
from opaline.pipeline.limits import Limits, check_limits
from opaline.scene.environment_files import EnvironmentMapError
from opaline.scene.environments import check_name

# How a request's mesh becomes a preset: a file on this machine (CLI, Python, batches) or
# an upload's id (HTTP). Given the request and the preset it names.
MeshResolver = Callable[[RenderRequest, Preset], Preset]


class UnknownEnvironment(PublicError, EnvironmentMapError, LookupError):
    """An environment name that is neither built in nor a file of the environments folder."""

    status, reason = 404, "unknown_environment"


@dataclass(frozen=True)
class Context:
    """What a request is prepared against where it runs."""

    limits: Limits
    meshes: MeshResolver
    environments_dir: Path | None = None
    # An environment may be a path to a file on this machine (CLI, Python, local batches);
    # never where a client's request is served.
    environment_paths: bool = False
    # False where another machine renders (``batch --server``): its folder decides.
    check_environments: bool = True


@dataclass(frozen=True)
class Prepared:
    request: RenderRequest
    preset: Preset  # the scene drawn: the mesh preset when the request names a mesh
    job: Job
    key: str
    # The preset the request names, also under a mesh (whose preset is named by the file's
    # digest): what the workers' cost model was calibrated on, and its name a metric's
    # label, from a set that uploads cannot grow.
    named: Preset
    # The scene's part of the key: the preset's, and an environment file's content.
    scene_key: str

    def query(self) -> dict[str, str]:
        """The canonical GET query's fields, spelled, without ``rev``."""
        return canonical_query(self.job, self.preset, self.request)

    def url(self) -> str:
        return canonical_url(self.query(), self.key)

    def with_job(self, job: Job) -> Prepared:
        """The same scene drawing another job (a turntable's frame), keyed anew."""
        return replace(self, job=job, key=job.cache_key(self.scene_key))


def scene(request: RenderRequest, named: Preset,
          context: Context) -> tuple[Preset, str, RenderRequest]:
    """The preset a request draws (``named``, or its mesh's if it names one) and its scene
    key, after checking that its environment exists: names are the built-ins plus the
    files of a folder, which the schema cannot list, so an unknown one is refused like an
    unknown preset. A file's content is part of the key: replaced under its name, it
    draws anew (and its canonical URL's rev changes) where the old image was answered.
    Where a map may be named by its path, the request names it by its absolute one, so
    that a key does not depend on where a command ran (a batch's up-to-date check did)."""
    preset = named
    if request.mesh is not None:
        preset = context.meshes(request, named)
    key = preset.scene_key()
    if request.environment is not None and context.check_environments:
        try:
            path = check_name(request.environment, context.environments_dir,
                              context.environment_paths)
        except EnvironmentMapError as exc:
            raise UnknownEnvironment(str(exc)) from None
        if path is not None:
            key = f"{key}+{known_file_digest(path)}"
            if context.environment_paths:
                # absolute(), not resolve(): a link to a content store's suffix-less blob
                # must keep its own name, which says it is a map
                request = request.model_copy(update={"environment": str(path.absolute())})
    return preset, key, request


def prepare(request: RenderRequest, context: Context) -> Prepared:
    named = get_preset(request.preset)
    preset, scene_key, request = scene(request, named, context)
    job = resolve(request, preset)
    check_limits(job, context.limits)
    return Prepared(request, preset, job, job.cache_key(scene_key), named, scene_key)
