"""Settings, read from ``OPALINE_*`` environment variables: what every layer imports.

The process's settings are the cached ``get_settings()`` (and, in the HTTP service,
the ``SettingsDep`` dependency of ``opaline.server.api``), so tests override the
dependency instead of patching globals. The command line and the Python API read the
same class: ``OPALINE_COST_BUDGET`` and ``OPALINE_PRESETS_DIR`` mean the same
everywhere. ``gl_backend`` reads ``OPALINE_GL_BACKEND``, the same variable that
``opaline.gl.context`` reads when no backend is passed explicitly.

The class (``opaline.service_settings``) needs pydantic-settings, a quarter of the
imports of a cold ``opaline render``: it is imported on first use of ``Settings`` or
``get_settings()``. The render path asks ``setting(name)``, which needs neither while
no ``OPALINE_*`` variable is set, since every setting then has its default.
"""

from __future__ import annotations

import os
from functools import lru_cache
from typing import TYPE_CHECKING, Any

# Re-exported: the plain values are read from here.
from opaline.setting_defaults import BACKENDS as BACKENDS
from opaline.setting_defaults import DEFAULT_COST_BUDGET as DEFAULT_COST_BUDGET
from opaline.setting_defaults import DEFAULTS
from opaline.setting_defaults import MAX_PIXELS as MAX_PIXELS
from opaline.setting_defaults import BackendName as BackendName

if TYPE_CHECKING:
    from pydantic import SecretStr

    # Re-exported (for type checkers: at run time __getattr__ below imports it on first use).
    from opaline.service_settings import Settings as Settings

ENV_PREFIX = "opaline_"  # pydantic-settings matches variable names case-insensitively


def __getattr__(name: str) -> Any:
    if name == "Settings":  # `from opaline.settings import Settings`, imported on first use
        from opaline.service_settings import Settings

        return Settings
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class SettingsError(ValueError):
    """An ``OPALINE_*`` variable the settings refuse, said in one line."""


@lru_cache
def get_settings() -> Settings:
    """The process's settings, read from the environment once. A variable the class
    refuses raises ``SettingsError`` naming it, its value and the rule it breaks (the
    command line prints that line instead of pydantic's traceback)."""
    from pydantic import ValidationError

    from opaline.service_settings import Settings

    try:
        return Settings()
    except ValidationError as exc:
        problems = [f"{ENV_PREFIX.upper()}{'_'.join(map(str, error['loc'])).upper()}="
                    f"{error.get('input')!r}: {error['msg']}" for error in exc.errors()]
        raise SettingsError("; ".join(problems)) from None


def setting(name: str) -> Any:
    """One of the settings a render reads, as ``get_settings()`` has it.

    Without any ``OPALINE_*`` variable (and before anything built the settings) the
    settings are their defaults, so those are returned without the class. With one,
    even another setting's, the class reads them all, so an invalid value fails as it
    does in the service."""
    if name in DEFAULTS and not get_settings.cache_info().currsize and not any(
            key.lower().startswith(ENV_PREFIX) for key in os.environ):
        return DEFAULTS[name]
    return getattr(get_settings(), name)


def secrets(value: SecretStr | None) -> list[bytes]:
    """The comma-separated secrets of a setting, as bytes for hmac."""
    raw = value.get_secret_value() if value is not None else ""
    return [part.strip().encode() for part in raw.split(",") if part.strip()]


# What the HTTP process holds besides its image cache (Python, FastAPI, NumPy, pydantic),
# and what one render may hold on top of a worker's limit before it is recycled: the
# largest frame read back and encoded (2048² RGBA float32, four copies at most).
HTTP_BASE_BYTES = 256 * 1024 * 1024
FRAME_BYTES = 4 * 2048 * 2048 * 16


def memory_budget_bytes(settings: Settings) -> int:
    """The most memory the service and its workers use together, whatever the requests:
    every cache is an LRU under its budget, and a worker past its limit is recycled."""
    mib = 1024 * 1024
    per_worker = settings.worker_max_rss_mb * mib + FRAME_BYTES
    check_worker = settings.worker_max_rss_mb * mib  # the mesh-check lane's: no GL, no frames
    return (HTTP_BASE_BYTES + settings.cache_bytes + 2 * FRAME_BYTES
            + settings.workers * per_worker + check_worker)
