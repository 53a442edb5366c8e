"""The gallery's measured pictures: every preset under its own lights and under the
studio, and real meshes with a set of presets under the studio and their default
lighting; each with the mean CIELAB chroma and lightness over the object's pixels."""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opaline.model.cielab import chroma, srgb_to_lab
from opaline.model.params import Quality, RenderRequest
from opaline.output.files import write_atomic
from opaline.resources import CHECKOUT

if TYPE_CHECKING:
    from opaline.local.pipeline import LocalRenderer

STUDIO = "studio"
# The presets that show every colour source and MDF on a mesh: the rotation model
# (sphere, cd-rom, nacre, perturbed-cube), films (nacre-film, oil-film, soap-bubble), a grating.
MESH_PRESETS = ("sphere", "nacre-film", "oil-film", "soap-bubble", "cd-rom", "nacre",
                "dvd-grating", "perturbed-cube")
# Real meshes not made by the project (tests/assets/README.md): a scan without UVs, a
# modelled mesh with UVs, a modelled one without. Only a checkout has them.
ASSETS = CHECKOUT / "tests" / "assets"
DEFAULT_MESHES = tuple(ASSETS / name for name in ("bunny.ply", "spot.obj", "teapot.obj"))
# The transparent render's alpha is coverage; half covered counts as the object's.
COVERED = 128


@dataclass(frozen=True)
class Shot:
    """One picture: a preset, optionally on a mesh, under an environment (None: the default,
    the preset's own lights, or on a mesh whatever a user's mesh gets)."""

    image: str  # file name under the gallery folder
    sheet: str  # the contact sheet it goes on
    preset: str
    mesh: Path | None = None
    environment: str | None = None

    def request(self, size: int, quality: Quality, transparent: bool = False) -> RenderRequest:
        # The mask leaves the backdrop out: a preset that shows its environment behind the
        # object would otherwise cover the whole frame.
        return RenderRequest(preset=self.preset, mesh=None if self.mesh is None else str(self.mesh),
                             environment=self.environment, width=size, height=size,
                             quality=quality, transparent=transparent or None,
                             environment_background=False if transparent else None)


def preset_shots(presets: Sequence[str]) -> list[Shot]:
    """Each preset under its own lights (the README's pictures) and under the studio."""
    own = [Shot(f"preset-{name}.png", "presets-default", name) for name in presets]
    studio = [Shot(f"studio-{name}.png", "presets-studio", name, environment=STUDIO)
              for name in presets]
    return own + studio


def mesh_shots(meshes: Sequence[Path], presets: Sequence[str]) -> list[Shot]:
    """Each mesh with each preset, under the studio and under a user's mesh's default."""
    shots = []
    for mesh in meshes:
        for lighting, environment in ((STUDIO, STUDIO), ("default", None)):
            shots += [Shot(f"{mesh.stem}-{name}-{lighting}.png", f"{mesh.stem}-{lighting}",
                           name, mesh, environment) for name in presets]
    return shots


def object_colour(image: bytes, mask: bytes) -> dict[str, float | int | None]:
    """Mean C*ab and L* of ``image``'s pixels where ``mask`` (the same view rendered
    transparent) is covered, and the mean C*ab of the rest: a film that lets the backdrop
    through carries the backdrop's chroma too. None where there are no such pixels."""
    import numpy as np
    from PIL import Image

    with Image.open(io.BytesIO(image)) as shown, Image.open(io.BytesIO(mask)) as cover:
        lab = srgb_to_lab(np.asarray(shown.convert("RGB"), dtype=np.float64) / 255.0)
        covered = np.asarray(cover.convert("RGBA"))[..., 3] >= COVERED

    def mean(values: Any) -> float | None:
        return round(float(values.mean()), 2) if values.size else None

    return {"chroma": mean(chroma(lab[covered])), "lightness": mean(lab[covered][:, 0]),
            "pixels": int(covered.sum()), "backdrop_chroma": mean(chroma(lab[~covered]))}


def lighting_name(renderer: LocalRenderer, request: RenderRequest) -> str:
    """The lighting the job got: its environment, or the preset's own lights."""
    return renderer.job(request).environment or "preset lights"


def render_shot(renderer: LocalRenderer, shot: Shot, out: Path, size: int,
                quality: Quality) -> dict[str, Any]:
    """Writes the shot's picture; its row of the gallery's table."""
    request = shot.request(size, quality)
    image = renderer.render_bytes(request)
    write_atomic(out / shot.image, image)
    mask = renderer.render_bytes(shot.request(size, quality, transparent=True))
    return {"image": shot.image, "sheet": shot.sheet, "preset": shot.preset,
            "mesh": None if shot.mesh is None else shot.mesh.name,
            "lighting": lighting_name(renderer, request), **object_colour(image, mask)}
