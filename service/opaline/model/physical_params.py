"""Request fields of the physically based iridescence sources (docs/physics.md).

``iridescence`` chooses where colour comes from: ``rotation`` is the paper's
per-channel rotated MDF (Kang et al. 2014, eq. 2); ``thin-film`` and
``grating`` keep the Ashikhmin-Shirley lobe (eq. 1, unrotated) as the
distribution of facet normals and take their colour from optics. Names and
units of the film follow glTF's KHR_materials_iridescence (IOR, thickness in
nm, minimum and maximum of the thickness field); the grating's pitch is in µm.

Two mixins: ``PhysicalFields`` (all optional, for requests and presets) and
``PhysicalMaterial`` (concrete defaults, for the resolved material). The
request and material models in ``params`` inherit them, so every range lives
here once and reaches the CLI, the OpenAPI schema and the page.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, Field

IridescenceName = Literal["rotation", "thin-film", "grating"]

# Film and substrate indices: real (lossless) dielectrics from air up to about
# diamond-and-beyond; absorbing substrates (metals) are out of scope.
FilmIor = Annotated[float, Field(ge=1.0, le=3.0)]
SubstrateIor = Annotated[float, Field(ge=1.0, le=4.0)]
# Thickness in nm: 0 is the bare substrate; beyond ~2 µm the colours of a film
# wash out to white within the 3 nm spectral sampling.
Thickness = Annotated[float, Field(ge=0.0, le=2000.0)]
# Pitch in µm: 0.2 (no visible first order below) to 20 (orders crowd the specular).
Pitch = Annotated[float, Field(ge=0.2, le=20.0)]
Orders = Annotated[int, Field(ge=1, le=8)]
# Groove depth in nm: the phase grating's efficiency J_m(a)²; the Bessel series
# in the shader is accurate in fp32 to a = 2π·depth/380 nm ≈ 6.6.
Depth = Annotated[float, Field(ge=0.0, le=400.0)]

DESCRIPTIONS = {
    "iridescence": "Colour source: 'rotation' (the paper's rotated MDF, eq. 2), 'thin-film' "
    "(Airy reflectance of a film) or 'grating' (1-D reflection grating along the tangent).",
    "film_ior": "Thin film's refractive index (KHR iridescenceIor), 1 … 3.",
    "film_thickness_min": "Film thickness in nm where the thickness field is 0 "
    "(KHR iridescenceThicknessMinimum), 0 … 2000.",
    "film_thickness_max": "Film thickness in nm where the thickness field is 1, and everywhere "
    "without a field (KHR iridescenceThicknessMaximum), 0 … 2000.",
    "substrate_ior": "Refractive index under the film (water 1.33, glass 1.5, air 1 for a "
    "soap film), 1 … 4.",
    "grating_pitch": "Grating period in µm across the grooves (CD 1.6, DVD 0.74), 0.2 … 20.",
    "grating_orders": "Highest diffraction order m summed (±1 … ±m, plus the specular m = 0), 1 … 8.",
    "grating_depth": "Groove depth in nm: sets each order's efficiency J_m(a)², 0 … 400.",
}


class PhysicalFields(BaseModel):
    """Optional physical-iridescence fields; ``None`` means "take the preset's value"."""

    iridescence: IridescenceName | None = Field(None, description=DESCRIPTIONS["iridescence"])
    film_ior: FilmIor | None = Field(None, description=DESCRIPTIONS["film_ior"])
    film_thickness_min: Thickness | None = Field(
        None, description=DESCRIPTIONS["film_thickness_min"]
    )
    film_thickness_max: Thickness | None = Field(
        None, description=DESCRIPTIONS["film_thickness_max"]
    )
    substrate_ior: SubstrateIor | None = Field(None, description=DESCRIPTIONS["substrate_ior"])
    grating_pitch: Pitch | None = Field(None, description=DESCRIPTIONS["grating_pitch"])
    grating_orders: Orders | None = Field(None, description=DESCRIPTIONS["grating_orders"])
    grating_depth: Depth | None = Field(None, description=DESCRIPTIONS["grating_depth"])


class PhysicalMaterial(BaseModel):
    """The physical fields of a resolved material, with KHR's defaults for the film."""

    iridescence: IridescenceName = "rotation"
    film_ior: FilmIor = 1.3
    film_thickness_min: Thickness = 100.0
    film_thickness_max: Thickness = 400.0
    substrate_ior: SubstrateIor = 1.5
    grating_pitch: Pitch = 1.6
    grating_orders: Orders = 3
    grating_depth: Depth = 150.0
