"""The JSON answers of the non-image routes, as the OpenAPI document shows them."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, Field


class PresetInfo(BaseModel):
    """A preset as the API shows it."""

    name: str
    description: str
    figure: str
    geometry: dict[str, Any] = Field(description="Geometry generator and its arguments.")
    tangents: str
    normal_map: dict[str, Any] | None
    defaults: dict[str, Any] = Field(description="The fields the preset sets itself.")
    resolved: dict[str, Any] = Field(
        description="What a request naming only this preset renders: every value resolved.")
    key_light: dict[str, float] | None = Field(
        None, description="Where the preset puts its key light, in degrees, as light_azimuth "
        "and light_elevation measure them.")


class Health(BaseModel):
    status: str = Field(description="Always 'ok': the process and its event loop answer.")


class Readiness(BaseModel):
    """What /readyz answers, with 200 or 503 alike."""

    ready: bool = Field(description="At least one worker process has a working GL context.")
    backend: str | None = Field(description="GL backend of the first ready worker.")
    renderer: str | None = Field(description="GL renderer string of the first ready worker.")
    queue_depth: int = Field(description="Jobs waiting for a render worker.")
    calibrated: bool = Field(description="Render times are predicted from this machine's "
                                         "measured timings (else from conservative defaults).")
    memory_budget_bytes: int = Field(
        description="The most memory the service and its workers use together (settings).")
    workers: list[dict[str, Any]] = Field(
        description="Each worker process: name, state (starting, ready, busy, failed, stopped), "
        "pid, renders, rss_bytes, restarts, its GL context's description, and the last error.")
    checks: list[dict[str, Any]] = Field(
        default_factory=list,
        description="The mesh-check lane's worker processes (uploads are parsed there, never "
        "in front of renders), as workers; a failed one fails uploads only, not readiness.")


class TierInfo(BaseModel):
    """A quality tier: what ``quality=<name>`` renders with unless the request overrides it."""

    name: str
    samples: int = Field(description="Samples per pixel.")
    wavelengths: int = Field(description="Wavelengths integrated (0: the paper's RGB model) "
                                         "for the rotation and grating sources.")
    film_wavelengths: int = Field(description="Wavelengths a thin film on a dielectric is "
                                              "integrated at (0: the RGB fast path, closed "
                                              "form over the colour weights).")
    metal_film_wavelengths: int = Field(description="The same for a film on a conductor.")
    stack_wavelengths: int = Field(description="The same for a stack of layers "
                                               "(film_stack_pairs > 0; 0: its 16-bin fast "
                                               "path).")
    aa: str = Field(description="Anti-aliasing: 'analytic' or 'none'.")
    environment_lights: int = Field(description="Directional lights an environment becomes "
                                                "where it is drawn as lights.")
    environment_samples: int = Field(description="Lobe samples per pixel that read the "
                                                 "environment map.")
    environment_samples_rotation: int = Field(
        description="The same for the rotation source's Ashikhmin-Shirley lobes (three of "
                    "them, one a channel).")
    environment_samples_grating: int = Field(
        description="The same for a grating: reads along the curve its orders leave by.")
