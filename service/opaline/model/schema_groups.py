"""The tuning page's layout in the RenderRequest schema (``x-groups``, ``x-group``,
``x-applies``, ``x-tier``), until each field declares its own.

Stand-in for the page: the lead's schema on main supersedes this module, which
can then be dropped with its one hook in ``params.RenderRequest``.
"""

from __future__ import annotations

from typing import Any

GROUPS: list[tuple[str, str, tuple[str, ...]]] = [
    ("material", "Material", ("mdf", "ex", "ey", "mu_f", "alpha", "beta", "theta1", "theta2",
                              "kd", "ks", "albedo", "f0")),
    ("physical", "Iridescence source", ("iridescence", "film_ior", "film_thickness_min",
                                        "film_thickness_max", "substrate_ior", "grating_pitch",
                                        "grating_orders", "grating_depth")),
    ("light", "Light", ("light_azimuth", "light_elevation")),
    ("output", "Output", ("width", "height", "quality", "format", "exposure", "tonemap",
                          "transparent")),
    ("scene", "Mesh and camera", ("mesh", "tangent_field", "tangent_axis", "camera_azimuth",
                                  "camera_elevation", "camera_distance")),
    ("environment", "Environment", ("environment", "environment_rotation",
                                    "environment_intensity", "environment_lights",
                                    "environment_background")),
    ("tier", "Quality tier overrides", ("samples", "wavelengths", "aa", "max_flip",
                                        "max_delta_e")),
]
ROTATION = {"iridescence": ["rotation"]}  # the paper's source; the physical ones use A-S
APPLIES: dict[str, dict[str, list[str]]] = {
    "mdf": ROTATION, "theta1": ROTATION, "theta2": ROTATION,
    "ex": {"mdf": ["ashikhmin"]}, "ey": {"mdf": ["ashikhmin"]},
    **{name: {"mdf": ["multipeak"], **ROTATION} for name in ("mu_f", "alpha", "beta")},
    **{name: {"iridescence": ["thin-film"]}
       for name in ("film_ior", "film_thickness_min", "film_thickness_max", "substrate_ior")},
    **{name: {"iridescence": ["grating"]}
       for name in ("grating_pitch", "grating_orders", "grating_depth")},
}
TIER = ("samples", "wavelengths", "aa", "environment_lights")


def add_groups(schema: dict[str, Any]) -> None:
    """json_schema_extra of RenderRequest: the keys above on the schema and its properties."""
    schema["x-groups"] = [{"id": gid, "title": title} for gid, title, _ in GROUPS]
    properties = schema.get("properties", {})
    for gid, _, names in GROUPS:
        for name in names:
            if name in properties:
                properties[name]["x-group"] = gid
    for name, applies in APPLIES.items():
        if name in properties:
            properties[name]["x-applies"] = applies
    for name in TIER:
        if name in properties:
            properties[name]["x-tier"] = True
