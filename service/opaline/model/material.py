"""Every material field, declared once: its type and range, default, unit, description,
and which colour source or MDF reads it.

``Material`` is the resolved material the renderer consumes. ``MaterialFields``,
the same fields all optional (``None``: take the preset's value), is generated
from it, so requests, presets, material files, the CLI's ``--help`` and the
OpenAPI schema all read one declaration. A field's ``x-applies`` (in the
schema) says under which ``iridescence`` / ``mdf`` it is read at all, and its
``x-group`` where the tuning page puts it.

``iridescence`` chooses where colour comes from: ``rotation`` is the paper's
per-channel rotated MDF (Kang et al. 2014, eq. 2); ``thin-film`` and
``grating`` keep the Ashikhmin-Shirley lobe (eq. 1, unrotated) as the
distribution of facet normals and take their colour from optics
(docs/physics.md). Names and units of the film follow glTF's
KHR_materials_iridescence (IOR, thickness in nm); the grating's pitch is in µm.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, create_model

TWO_PI = 2.0 * math.pi
STRICT = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

IridescenceName = Literal["rotation", "thin-film", "grating"]
MdfName = Literal["ashikhmin", "multipeak"]
SubstrateName = Literal["dielectric", "conductor"]
MetalName = Literal["gold", "silver", "copper", "aluminium", "titanium", "iron", "bismuth",
                    "artist"]

Exponent = Annotated[float, Field(ge=0.0, le=1e6)]
Frequency = Annotated[float, Field(ge=0.0, le=1000.0)]
Anisotropy = Annotated[float, Field(ge=0.0, le=1000.0)]
Angle = Annotated[float, Field(ge=-TWO_PI, le=TWO_PI)]
Weight = Annotated[float, Field(ge=0.0, le=100.0)]
Unit = Annotated[float, Field(ge=0.0, le=1.0)]
# Film and substrate indices: real (lossless) dielectrics from air up to about
# diamond-and-beyond; absorbing substrates are conductors (``substrate``, ``metal``).
FilmIor = Annotated[float, Field(ge=1.0, le=3.0)]
SubstrateIor = Annotated[float, Field(ge=1.0, le=4.0)]
# Thickness in nm: 0 is the bare substrate; beyond ~2 µm the colours of a film
# wash out to white within the 3 nm spectral sampling.
Thickness = Annotated[float, Field(ge=0.0, le=2000.0)]
# A stack's periods: 16 pairs are 32 layers, model.multilayer.MAX_LAYERS.
MAX_STACK_PAIRS = 16
StackPairs = Annotated[int, Field(ge=0, le=MAX_STACK_PAIRS)]
# Pitch in µm: 0.2 (no visible first order below) to 20 (orders crowd the specular).
Pitch = Annotated[float, Field(ge=0.2, le=20.0)]
Orders = Annotated[int, Field(ge=1, le=8)]
# Groove depth in nm: the phase grating's efficiency J_m(a)²; the Bessel series
# in the shader is accurate in fp32 to a = 2π·depth/380 nm ≈ 6.6.
Depth = Annotated[float, Field(ge=0.0, le=400.0)]


def about(group: str, unit: str | None = None, **applies: tuple[str, ...]) -> dict[str, Any]:
    """A field's schema extras: its page group, unit, and the selector values it is read
    under (none: always)."""
    extra: dict[str, Any] = {"x-group": group}
    if unit is not None:
        extra["x-unit"] = unit
    if applies:
        extra["x-applies"] = {name: list(values) for name, values in applies.items()}
    return extra


PHYSICAL, MATERIAL, COAT = "physical", "material", "coat"
FILM, GRATING, ROTATION = ("thin-film",), ("grating",), ("rotation",)
DIELECTRIC, CONDUCTOR, ARTIST = ("dielectric",), ("conductor",), ("artist",)


class Material(BaseModel):
    """A fully specified material, as the renderer consumes it."""

    model_config = STRICT

    iridescence: IridescenceName = Field(
        "rotation", json_schema_extra=about(PHYSICAL),
        description="Colour source: 'rotation' (the paper's rotated MDF, eq. 2), 'thin-film' "
        "(Airy reflectance of a film) or 'grating' (1-D reflection grating along the tangent).")
    film_ior: FilmIor = Field(
        1.3, json_schema_extra=about(PHYSICAL, iridescence=FILM),
        description="Thin film's refractive index (KHR iridescenceIor), 1 … 3.")
    film_weight: Unit = Field(
        1.0, json_schema_extra=about(PHYSICAL, iridescence=FILM),
        description="How much of the film there is (KHR iridescenceFactor, OpenPBR "
        "thin_film_weight): the specular colour is mix(bare substrate, film, weight); 0 is the "
        "substrate's own Fresnel reflectance, 1 the whole film, 0 … 1.")
    film_thickness_min: Thickness = Field(
        100.0, json_schema_extra=about(PHYSICAL, "nm", iridescence=FILM),
        description="Film thickness in nm where the thickness field is 0 "
        "(KHR iridescenceThicknessMinimum), 0 … 2000.")
    film_thickness_max: Thickness = Field(
        400.0, json_schema_extra=about(PHYSICAL, "nm", iridescence=FILM),
        description="Film thickness in nm where the thickness field is 1, and everywhere "
        "without a field (KHR iridescenceThicknessMaximum), 0 … 2000.")
    film_stack_pairs: StackPairs = Field(
        0, json_schema_extra=about(PHYSICAL, iridescence=FILM),
        description="Periods of a multilayer stack, 0 … 16: 0 is the single film; N > 0 makes "
        "the film N pairs of layers on the substrate, each the film's layer (film_ior, its "
        "thickness) over a spacer (film_spacer_ior, film_spacer_thickness): a Bragg mirror, "
        "a Morpho scale's lamellae. A thickness field scales both layers.")
    film_spacer_ior: FilmIor = Field(
        1.46, json_schema_extra=about(PHYSICAL, iridescence=FILM),
        description="A stack's spacer layer's refractive index (silica 1.46, air 1 between "
        "a wing scale's lamellae), 1 … 3; read where film_stack_pairs > 0.")
    film_spacer_thickness: Thickness = Field(
        100.0, json_schema_extra=about(PHYSICAL, "nm", iridescence=FILM),
        description="A stack's spacer thickness in nm where the film's is "
        "film_thickness_max, 0 … 2000; read where film_stack_pairs > 0.")
    substrate_ior: SubstrateIor = Field(
        1.5, json_schema_extra=about(PHYSICAL, iridescence=FILM, substrate=DIELECTRIC),
        description="Refractive index under the film (water 1.33, glass 1.5, air 1 for a "
        "soap film), 1 … 4.")
    substrate: SubstrateName = Field(
        "dielectric", json_schema_extra=about(PHYSICAL, iridescence=FILM),
        description="What is under the film: 'dielectric' (the real index substrate_ior) or "
        "'conductor' (a metal's n + ik per wavelength: metal). A film of thickness 0 leaves "
        "the bare substrate.")
    metal: MetalName = Field(
        "gold", json_schema_extra=about(PHYSICAL, iridescence=FILM, substrate=CONDUCTOR),
        description="The conductor under the film, from published n, k: gold, silver, copper "
        "(Johnson & Christy 1972), aluminium (Rakić 1995), titanium, iron (Johnson & Christy "
        "1974), bismuth (Hagemann 1975); or 'artist': metal_f0 and metal_edge_tint "
        "(Gulbrandsen 2014).")
    metal_f0: tuple[Unit, Unit, Unit] = Field(
        (0.944, 0.776, 0.373),
        json_schema_extra=about(PHYSICAL, iridescence=FILM, substrate=CONDUCTOR, metal=ARTIST),
        description="The artist metal's reflectance at normal incidence, linear RGB, each "
        "0 … 1.")
    metal_edge_tint: tuple[Unit, Unit, Unit] = Field(
        (0.998, 0.981, 0.751),
        json_schema_extra=about(PHYSICAL, iridescence=FILM, substrate=CONDUCTOR, metal=ARTIST),
        description="The artist metal's edge tint (Gulbrandsen 2014: its colour toward "
        "grazing), linear RGB, each 0 … 1.")
    grating_pitch: Pitch = Field(
        1.6, json_schema_extra=about(PHYSICAL, "µm", iridescence=GRATING),
        description="Grating period in µm across the grooves (CD 1.6, DVD 0.74), 0.2 … 20.")
    grating_orders: Orders = Field(
        3, json_schema_extra=about(PHYSICAL, iridescence=GRATING),
        description="Highest diffraction order m summed (±1 … ±m, plus the specular m = 0), "
        "1 … 8.")
    grating_depth: Depth = Field(
        150.0, json_schema_extra=about(PHYSICAL, "nm", iridescence=GRATING),
        description="Groove depth in nm: sets each order's efficiency J_m(a)², 0 … 400.")
    mdf: MdfName = Field(
        "multipeak", json_schema_extra=about(MATERIAL, iridescence=ROTATION),
        description="Microfacet distribution: 'ashikhmin' (eq. 1) or 'multipeak' (eqs. 3-4).")
    ex: Exponent = Field(
        100.0, json_schema_extra=about(MATERIAL, mdf=("ashikhmin",)),
        description="Ashikhmin-Shirley exponent along the tangent (eq. 1), 0 … 1e6.")
    ey: Exponent = Field(
        10.0, json_schema_extra=about(MATERIAL, mdf=("ashikhmin",)),
        description="Ashikhmin-Shirley exponent along the bitangent (eq. 1), 0 … 1e6.")
    mu_f: Frequency = Field(
        8.5, json_schema_extra=about(MATERIAL, mdf=("multipeak",), iridescence=ROTATION),
        description="Multi-peak frequency: rings across the MDF disc (eq. 4), 0 … 1000.")
    alpha: Anisotropy = Field(
        2.0, json_schema_extra=about(MATERIAL, mdf=("multipeak",), iridescence=ROTATION),
        description="Multi-peak anisotropy along the tangent (eq. 4), 0 … 1000.")
    beta: Anisotropy = Field(
        1.2, json_schema_extra=about(MATERIAL, mdf=("multipeak",), iridescence=ROTATION),
        description="Multi-peak anisotropy along the bitangent (eq. 4), 0 … 1000.")
    theta1: Angle = Field(
        0.1, json_schema_extra=about(MATERIAL, "rad", iridescence=ROTATION),
        description="Rotation of the green channel's MDF in radians (eq. 2), -2π … 2π.")
    theta2: Angle = Field(
        0.2, json_schema_extra=about(MATERIAL, "rad", iridescence=ROTATION),
        description="Rotation of the blue channel's MDF in radians (eq. 2), -2π … 2π.")
    kd: Weight = Field(0.0, json_schema_extra=about(MATERIAL),
                       description="Diffuse weight, 0 … 100.")
    ks: Weight = Field(1.0, json_schema_extra=about(MATERIAL),
                       description="Specular weight, 0 … 100.")
    albedo: tuple[Unit, Unit, Unit] = Field(
        (0.5, 0.5, 0.5), json_schema_extra=about(MATERIAL),
        description="Diffuse colour, linear RGB, each 0 … 1.")
    f0: Unit = Field(
        1.0, json_schema_extra=about(MATERIAL),
        description="Schlick reflectance at normal incidence, 0 … 1 (1 turns Fresnel off).")
    coat_weight: Unit = Field(
        0.0, json_schema_extra=about(COAT),
        description="How much clear coat covers the material (KHR clearcoatFactor, OpenPBR "
        "coat_weight), 0 … 1: the coat reflects weight·F_coat of the light in a lobe of its "
        "own and dims what is below by as much; 0 is no coat.")
    coat_roughness: Unit = Field(
        0.0, json_schema_extra=about(COAT),
        description="The coat's roughness as glTF means it (KHR clearcoatRoughnessFactor: "
        "the GGX width is its square), 0 … 1; below 0.02 it is 0.02 (a mirror-sharp lobe).")
    coat_ior: FilmIor = Field(
        1.5, json_schema_extra=about(COAT),
        description="The coat's refractive index (lacquer 1.5, KHR's fixed value; OpenPBR "
        "coat_ior 1.6), 1 … 3: its Fresnel reflectance against air.")


MATERIAL_FIELDS = tuple(Material.model_fields)
# The material fields an MDF plot depends on (Figs. 2-8): the rest (colour source, film,
# grating, coat, kd ...) leave it alone, and a plot's key and URL ignore them.
MDF_PLOT_FIELDS = ("mdf", "ex", "ey", "mu_f", "alpha", "beta", "theta1", "theta2")


def _optional(name: str) -> Any:
    """``Material``'s field ``name`` as an override: the same type, range, description and
    extras, ``None`` by default."""
    field = Material.model_fields[name]
    annotation: Any = field.annotation
    if field.metadata:  # the range (ge, le) pydantic keeps apart from the type
        annotation = Annotated[(annotation, *field.metadata)]
    return (annotation | None, Field(None, description=field.description,
                                     json_schema_extra=field.json_schema_extra))


# Generated, so that a new material field is one declaration in ``Material``.
MaterialFields: type[BaseModel] = create_model(
    "MaterialFields", __config__=STRICT, __doc__='Material parameters; ``None`` means "take '
    'the preset\'s value".', **{name: _optional(name) for name in MATERIAL_FIELDS})
