"""The shapes quality=auto reads (model/auto.py): a material's difficulty, the measured
table ``quality_table.json`` as bench/accuracy_table.py writes it, and what a job shows
of auto's pick."""

from __future__ import annotations

from typing import Literal, Protocol, TypedDict

from opaline.model.tiers import AntiAliasName, Tier

# difficulty's numbers, each growing with the error
Measure = Literal["rate", "turn", "span", "brightness"]


class Difficulty(TypedDict):
    mdf: str
    rate: float
    turn: float
    span: float
    brightness: float
    size: int


class Point(TypedDict):
    """One measured setting."""

    samples: int
    wavelengths: int
    aa: AntiAliasName
    ms: float


class MeasuredMaterial(TypedDict):
    variant: str
    difficulty: Difficulty
    theta: list[float]
    flip: list[float]  # one per point, in the points' order
    de2000_p95: list[float]


class PresetEntry(TypedDict):
    digest: str  # the preset's scene and defaults (auto.preset_digest)
    compiled: str  # the sources of its programs as they compile (gl/variant_source.py)
    programs: list[str]  # those program variants, as variant_source.variant_label writes them
    points: list[Point]
    materials: list[MeasuredMaterial]


class Table(TypedDict):
    command: str
    date: str
    size: int
    machine: str
    presets: dict[str, PresetEntry]


class Picked(Protocol):
    """What auto's headers read of a job (model/request.py's Job, which imports auto)."""

    @property
    def tier(self) -> Tier: ...

    @property
    def samples(self) -> int: ...

    @property
    def wavelengths(self) -> int: ...

    @property
    def aa(self) -> str: ...
