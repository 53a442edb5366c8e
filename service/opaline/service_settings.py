"""The service's settings class, read from ``OPALINE_*`` environment variables.

Imported only where the class itself is needed (the HTTP service, ``opaline serve``):
pydantic-settings alone costs a cold ``opaline render`` about 25 ms. Everything else
reaches it through ``opaline.settings`` (``get_settings()``, ``setting(name)``), which
is also where the plain values used here are defined.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import Field, SecretStr, field_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from opaline.setting_defaults import (
    DEFAULT_COST_BUDGET,
    DEFAULT_ENVIRONMENTS_DIR,
    DEFAULT_MESH_MAX_TRIANGLES,
    MAX_PIXELS,
    BackendName,
)


class Settings(BaseSettings):
    """Everything the HTTP service can be configured with."""

    model_config = SettingsConfigDict(env_prefix="OPALINE_", extra="ignore", frozen=True)

    gl_backend: BackendName = Field(
        "egl", description="Headless GL backend of the render workers.")
    host: str = Field("127.0.0.1", description="Address `opaline serve` binds.")
    port: int = Field(8000, ge=1, le=65535, description="Port `opaline serve` binds.")
    workers: int = Field(
        1, ge=1, le=16,
        description="Render worker processes, one GL context each. 1 is the measured best on a "
                    "2-core llvmpipe machine (bench/results/http_load.md).")
    lp_threads: int | None = Field(
        None, ge=1, le=256,
        description="llvmpipe threads per worker (LP_NUM_THREADS); default: cores ÷ workers.")
    queue_size: int = Field(
        32, ge=1, le=10_000, description="Jobs waiting for a worker before 503.")
    deadline_s: float = Field(
        10.0, gt=0, le=600,
        description="Longest a request may wait for its image. A job predicted to take longer "
                    "is refused at once (422), one that would miss it behind the queue gets "
                    "503, and a job still queued when it passes leaves the queue (503).")
    render_timeout_s: float = Field(
        30.0, gt=0, le=3600,
        description="A render running longer than this has its worker killed and replaced "
                    "(the watchdog); the request gets 503.")
    calibrate: bool = Field(
        True, description="Time a few renders per preset at start-up to predict render times.")
    worker_max_renders: int = Field(
        1000, ge=1, description="A worker is recycled after this many renders.")
    worker_max_rss_mb: int = Field(
        1024, ge=256, description="A worker whose memory passes this after a render is recycled.")
    worker_programs: int = Field(
        64, ge=4, le=4096, description="Shader variants a worker keeps compiled (LRU).")
    worker_scene_mb: int = Field(
        128, ge=8, description="Bytes of uploaded meshes and normal maps a worker keeps (LRU).")
    worker_target_mb: int = Field(
        256, ge=218, description="Bytes of framebuffers a worker keeps (LRU); at least one "
                                 "2048² set (218 MB).")
    max_turntables: int = Field(
        2, ge=1, le=64,
        description="Turntables rendered at once; one more is refused with 429 and Retry-After. "
                    "Their frames share one lane per worker, so other requests always find "
                    "room in the queue.")
    retry_after_s: int = Field(1, ge=1, le=3600, description="Retry-After sent with a 503.")
    cache_bytes: int = Field(
        256 * 1024 * 1024, ge=0, description="Byte budget of the in-memory image cache (0: off).")
    cache_max_age_s: int = Field(
        3600, ge=0, description="Cache-Control max-age of image answers to GET.")
    max_body_bytes: int = Field(16 * 1024, ge=256, description="Largest accepted request body.")
    max_width: int = Field(MAX_PIXELS, ge=16, le=MAX_PIXELS, description="Largest image width.")
    max_height: int = Field(MAX_PIXELS, ge=16, le=MAX_PIXELS, description="Largest image height.")
    cost_budget: int = Field(
        DEFAULT_COST_BUDGET, ge=1,
        description="Largest width×height×samples×max(wavelengths, 3) a request may cost.")
    max_connections: int = Field(
        1024, ge=1, description="Open connections the service accepts before answering 503.")
    # Access control (docs/design.md, "Access control"): off until a key or a secret is set.
    api_keys: SecretStr | None = Field(
        None, description="Comma-separated API keys; setting any turns access control on: /v1 "
                          "and /metrics then need X-API-Key (or Authorization: Bearer) or, for "
                          "GET images, a signed URL.")
    signing_key: SecretStr | None = Field(
        None, description="Secret for HMAC-SHA256 signed GET URLs (sig=, optional exp=); "
                          "setting it turns access control on.")
    rate_limit_per_s: float = Field(
        0.0, ge=0, description="Requests per second per API key or client address (0: off); "
                               "over it: 429 with Retry-After.")
    rate_burst: int = Field(20, ge=1, description="Requests a key or address may burst.")
    # Connection hygiene (opaline.server.connections)
    header_timeout_s: float = Field(
        10.0, gt=0, le=600, description="A connection must send a request's headers within this.")
    body_timeout_s: float = Field(
        10.0, gt=0, le=600, description="A request's body must arrive within this, plus a "
                                        "second for every min_body_rate bytes that arrived.")
    min_body_rate: int = Field(
        16384, ge=1, description="Bytes a second that earn a request's body more time past "
                                 "body_timeout_s: a slower one is cut off with 408.")
    write_timeout_s: float = Field(
        30.0, gt=0, le=3600, description="A client that reads nothing for this long is dropped.")
    max_connections_per_client: int = Field(
        64, ge=1, description="Open connections one client address may hold; beyond: refused.")
    presets_dir: Path | None = Field(
        None, description="Folder of scene presets (TOML) used instead of the built-in ones.")
    mesh_max_bytes: int = Field(
        64 * 1024 * 1024, ge=1024, description="Largest mesh file POST /v1/meshes accepts (413).")
    mesh_max_triangles: int = Field(
        DEFAULT_MESH_MAX_TRIANGLES, ge=1, le=50_000_000,
        description="Most triangles a mesh may have (422).")
    mesh_store_bytes: int = Field(
        1024 * 1024 * 1024, ge=1024,
        description="Bytes of uploaded meshes kept on disk; the least recently used go first.")
    mesh_store_dir: Path | None = Field(
        None, description="Where uploaded meshes are kept (default: a temporary folder).")
    state_url: str | None = Field(
        None, pattern=r"^rediss?://",
        description="Where uploaded meshes and turntable jobs live. Unset: this process "
                    "(meshes in OPALINE_MESH_STORE_DIR, turntables in memory); "
                    "redis://host:port/db: a Redis every replica shares (docs/deployment.md).")
    state_timeout_s: float = Field(
        1.0, gt=0, le=60, description="A state store call that takes longer answers 503.")
    state_lease_s: float = Field(
        10.0, gt=0, le=600,
        description="A turntable whose replica has not renewed its lease for this long is "
                    "continued by the replica that next answers for it.")
    turntable_keep_s: int = Field(
        3600, ge=1, description="How long a turntable's status and result are kept.")
    turntable_result_bytes: int = Field(
        64 * 1024 * 1024, ge=1024,
        description="Bytes of finished turntables' animations kept in this process (without "
                    "OPALINE_STATE_URL), the oldest forgotten first; part of the HTTP "
                    "process's 256 MB in the memory budget.")
    meshes_dir: Path | None = Field(
        None, description="A folder of mesh files requests may name by file name (mesh=NAME).")
    environments_dir: Path | None = Field(
        DEFAULT_ENVIRONMENTS_DIR,
        description="A folder of HDR environments (.hdr, .exr) requests may name.")
    warmup: bool = Field(
        True, description="Render a tiny image on each worker at start-up, so the first "
                          "request does not pay for shader compilation.")

    @field_validator("gl_backend", mode="before")
    @classmethod
    def _lower(cls, value: object) -> object:
        return value.strip().lower() if isinstance(value, str) else value  # as context.py reads it
