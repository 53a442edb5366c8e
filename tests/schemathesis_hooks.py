"""Schemathesis hooks for the chaos suite (loaded through SCHEMATHESIS_HOOKS).

``positive_data_acceptance`` demands that every schema-valid request succeed.
Two refusals of valid data are this service's documented limits, which a
schema cannot express because they depend on a combination of fields and on the
machine: the cost budget and the render deadline (``cost``, ``too_slow``) and
the configured maximum size (``limit``). One more is a rule about the bytes of
a body the schema can only call "binary": POST /v1/meshes refuses a file that
is not a mesh (``invalid_mesh``). This check is that one, except for those
422s (each documented in its route's responses); every other check runs
unchanged.
"""

from __future__ import annotations

import schemathesis
from schemathesis.specs.openapi.checks import positive_data_acceptance

LIMITS = {"cost", "too_slow", "limit",
          "invalid_mesh",  # any binary is schema-valid; only mesh files are meshes
          "budget_with_tier"}  # max_flip/max_delta_e exclude a named tier: a cross-field rule


@schemathesis.check
def positive_data_accepted_within_limits(ctx, response, case):
    if response.status_code == 422:
        try:
            error = response.json().get("error")
        except Exception:  # noqa: BLE001 - not JSON: let the real check judge it
            error = None
        if error in LIMITS:
            return None
    return positive_data_acceptance(ctx, response, case)
