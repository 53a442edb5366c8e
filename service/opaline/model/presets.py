"""Scene presets: TOML files in ``presets/``, validated when loaded.

A preset is a scene (geometry, tangent field, normal map, camera, lights,
background) plus ``[defaults]``, which parse into the same model as a render
request's fields: a preset is a request with a scene attached. The merge
order is the built-in defaults, then the preset's, then the request's.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from functools import cache
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from opaline.errors import PublicError
from opaline.model.material import Unit
from opaline.model.params import STRICT, RenderFields, describe_errors
from opaline.model.projection import MeshProjection
from opaline.resources import presets_dir
from opaline.scene import geometry, meshfile, normalmaps, thickness

Vec3 = tuple[float, float, float]
NonNegative3 = tuple[
    Annotated[float, Field(ge=0.0)],
    Annotated[float, Field(ge=0.0)],
    Annotated[float, Field(ge=0.0)],
]
Colour = tuple[Unit, Unit, Unit]


class PresetError(ValueError):
    """A preset file is missing or invalid; the message names the file and field."""


class Camera(BaseModel):
    model_config = STRICT
    eye: Vec3
    target: Vec3 = (0.0, 0.0, 0.0)
    up: Vec3 = (0.0, 1.0, 0.0)
    fov_deg: Annotated[float, Field(gt=1.0, lt=170.0)] = 35.0


class Light(BaseModel):
    model_config = STRICT
    type: Literal["point", "directional"]
    # Point: position. Directional: direction toward the light.
    position: Vec3
    irradiance: NonNegative3 = (1.0, 1.0, 1.0)


class Generator(BaseModel):
    """A named generator and its keyword arguments (checked by the generator)."""

    model_config = ConfigDict(extra="allow", frozen=True)
    kind: str

    @property
    def args(self) -> dict[str, Any]:
        return dict(self.model_extra or {})


class Preset(BaseModel):
    model_config = STRICT
    name: str
    description: str
    figure: str = ""
    geometry: Generator
    tangents: Literal["uv", "concentric"] = "uv"
    normal_map: Generator | None = None
    # Film thickness in [0, 1] over uv, mapped to [film_thickness_min, max] (thin film only).
    thickness_map: Generator | None = None
    # The film's weight in [0, 1] over uv, times film_weight (a .glb's KHR iridescenceTexture).
    weight_map: Generator | None = None
    # How a user's mesh takes the maps: its UVs where it has them ("auto"), or always by
    # object-space projection ("object": maps whose look is their scale, such as nacre).
    mesh_projection: MeshProjection = "auto"
    # A free film (soap bubble): the background shows through what the film does not reflect.
    transmission: bool = False
    rotation_deg: Vec3 = (0.0, 0.0, 0.0)
    camera: Camera
    lights: Annotated[list[Light], Field(min_length=1, max_length=8)]
    background: Colour = (0.0, 0.0, 0.0)
    ambient: NonNegative3 = (0.0, 0.0, 0.0)
    defaults: RenderFields = RenderFields()

    def scene_key(self) -> str:
        """Hash of everything that shapes the scene, for cache keys."""
        scene = self.model_dump(exclude={"defaults", "description", "figure"}, mode="json")
        if self.geometry.kind != "file":
            # It shapes only a user's mesh: the presets' own scenes keep their keys.
            del scene["mesh_projection"]
        if self.weight_map is None:  # keys from before the weight map stay what they were
            del scene["weight_map"]
        return hashlib.sha256(json.dumps(scene, sort_keys=True).encode()).hexdigest()[:16]


def load_preset_file(path: Path) -> Preset:
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise PresetError(f"preset {path.name}: {exc}") from exc
    data.setdefault("name", path.stem)
    try:
        preset = Preset.model_validate(data)
    except ValidationError as exc:
        problems = describe_errors(exc, Preset)
        raise PresetError(f"preset {path.name}: " + "; ".join(problems)) from exc
    _check_generators(path.name, preset)
    return preset


def _check_generators(filename: str, preset: Preset) -> None:
    try:
        build_assets(preset)
        build_thickness(preset)
        build_weight(preset)
    except ValueError as exc:
        raise PresetError(f"preset {filename}: {exc}") from exc


_assets: dict[str, tuple[Any, Any]] = {}


def _map_args(generator: Generator) -> dict[str, Any]:
    """A map generator's arguments; a file map's path is relative to the presets folder."""
    args = generator.args
    if generator.kind == "file":
        args["path"] = str(presets_dir() / args.get("path", ""))
    return args


def build_assets(preset: Preset) -> tuple[Any, Any]:
    """The preset's mesh and normal map (or None), generated once per scene."""
    if preset.geometry.kind == "file":
        # A user's mesh: loaded (and bounded in number) by meshfile, never kept here; the
        # preset's normal map, projected onto it (model.projection), is.
        return meshfile.mesh_file(**preset.geometry.args), _normal_map(preset.normal_map)
    key = preset.scene_key()
    if key not in _assets:
        mesh = geometry.build(preset.geometry.kind, **preset.geometry.args)
        _assets[key] = (mesh, _normal_map(preset.normal_map))
    return _assets[key]


_normal_maps: dict[str, Any] = {}


def _normal_map(generator: Generator | None) -> Any:
    """A normal map (or None), generated once per generator: every mesh shares its preset's."""
    if generator is None:
        return None
    key = json.dumps(generator.model_dump(mode="json"), sort_keys=True)
    if key not in _normal_maps:
        _normal_maps[key] = normalmaps.build(generator.kind, **_map_args(generator))
    return _normal_maps[key]


_film_fields: dict[tuple[str, str], Any] = {}


def _film_field(preset: Preset, which: str, generator: Generator | None) -> Any:
    key = (preset.scene_key(), which)
    if key not in _film_fields:
        field = None
        if generator is not None:
            field = thickness.build(generator.kind, **_map_args(generator))
        _film_fields[key] = field
    return _film_fields[key]


def build_thickness(preset: Preset) -> Any:
    """The preset's film-thickness field (or None), generated once per scene."""
    return _film_field(preset, "thickness", preset.thickness_map)


def build_weight(preset: Preset) -> Any:
    """The preset's film-weight field (or None), generated once per scene."""
    return _film_field(preset, "weight", preset.weight_map)


@cache
def all_presets() -> dict[str, Preset]:
    """Every preset, validated; raises PresetError naming the first bad file."""
    found = {}
    for path in sorted(presets_dir().glob("*.toml")):
        preset = load_preset_file(path)
        found[preset.name] = preset
    return found


class UnknownPreset(PublicError, KeyError):
    status, reason = 404, "unknown_preset"

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(name)

    def __str__(self) -> str:
        return f"preset={self.name!r} is not known: choose one of {', '.join(all_presets())}"


@cache
def _named_file(name: str, folder: Path) -> Preset | None:
    """The preset in ``NAME.toml`` if that file names itself ``name`` (most do)."""
    path = folder / f"{name}.toml"
    if "/" in name or "\\" in name or not path.is_file():
        return None
    preset = load_preset_file(path)
    return preset if preset.name == name else None


def get_preset(name: str) -> Preset:
    """One preset. Its own file is read first, so a one-off render does not load and
    build every preset (the nacre normal map alone took 0.2 s of a cold ``opaline
    render``); anything else falls back to ``all_presets``, which also checks them all."""
    if all_presets.cache_info().currsize == 0:
        found = _named_file(name, presets_dir())
        if found is not None:
            return found
    try:
        return all_presets()[name]
    except KeyError:
        raise UnknownPreset(name) from None
