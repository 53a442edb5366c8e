"""Plain values of the settings: backend names, size and cost limits, and the defaults
the render path reads. Kept apart from the pydantic-settings class
(``opaline.service_settings``) so that a render does not import pydantic-settings."""

from __future__ import annotations

from pathlib import Path
from typing import Literal, get_args

BackendName = Literal["egl", "osmesa", "auto"]
BACKENDS: tuple[str, ...] = get_args(BackendName)
# 2048² at 64 samples in RGB: the largest image at the `reference` tier's sample count.
DEFAULT_COST_BUDGET = 2048 * 2048 * 64 * 3

MAX_PIXELS = 2048  # params.Pixels' upper bound: settings may lower it, never raise it

DEFAULT_MESH_MAX_TRIANGLES = 2_000_000
DEFAULT_ENVIRONMENTS_DIR: Path | None = None

# The defaults of the settings a render reads (``opaline.settings.setting``); the settings
# class takes its defaults for these fields from here (each by its own typed name above).
DEFAULTS: dict[str, int | Path | None] = {
    "cost_budget": DEFAULT_COST_BUDGET,
    "mesh_max_triangles": DEFAULT_MESH_MAX_TRIANGLES,
    "environments_dir": DEFAULT_ENVIRONMENTS_DIR,
}
