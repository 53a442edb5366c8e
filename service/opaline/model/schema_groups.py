"""The tuning page's layout in the RenderRequest schema: ``x-groups`` (the groups' order
and titles), ``x-group`` of the fields that are not the material's, ``x-tier`` of the
fields a quality tier sets.

The material's fields declare their own group and what reads them (``x-applies``) where
they are declared (``opaline.model.material``); this module places the rest.
"""

from __future__ import annotations

from typing import Any

from opaline.model.tiers import TIERS

GROUPS: list[tuple[str, str, tuple[str, ...]]] = [
    ("material", "Material", ()),
    ("physical", "Iridescence source", ()),
    ("coat", "Clear coat", ()),
    ("light", "Light", ("light_azimuth", "light_elevation")),
    ("output", "Output", ("width", "height", "quality", "format", "exposure", "tonemap",
                          "color_space", "transparent")),
    ("scene", "Mesh and camera", ("mesh", "tangent_field", "tangent_axis", "mesh_up", "camera_azimuth",
                                  "camera_elevation", "camera_distance")),
    ("environment", "Environment", ("environment", "environment_rotation",
                                    "environment_intensity", "environment_lights",
                                    "environment_samples", "environment_background",
                                    "environment_blur")),
    ("tier", "Quality tier overrides", ("samples", "wavelengths", "aa", "max_flip",
                                        "max_delta_e")),
]
# What a tier sets and a request may override one by one.
TIER = (*TIERS["draft"].render_settings(), "environment_lights", "environment_samples")


def add_groups(schema: dict[str, Any]) -> None:
    """json_schema_extra of RenderRequest: the keys above on the schema and its properties."""
    schema["x-groups"] = [{"id": gid, "title": title} for gid, title, _ in GROUPS]
    properties = schema.get("properties", {})
    for gid, _, names in GROUPS:
        for name in names:
            if name in properties:
                properties[name]["x-group"] = gid
    for name in TIER:
        if name in properties:
            properties[name]["x-tier"] = True
