"""The quality tiers: what each one renders with, as one typed value.

A ``Tier`` owns every knob a quality level sets: samples, wavelengths,
anti-aliasing and the number of lights an environment becomes. The named
tiers are points on the measured speed/accuracy fronts (docs/accuracy.md);
``quality=auto`` makes one of its own (``model/auto.py``), with the
measurement that chose it. A request may still override samples,
wavelengths, AA and environment lights one by one; the ``Job`` keeps its tier
and the values it ends up with.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, get_args

if TYPE_CHECKING:
    from opaline.model.material import Material

TierName = Literal["draft", "standard", "high", "reference"]
QualityName = Literal["draft", "standard", "high", "reference", "auto"]
AntiAliasName = Literal["none", "analytic"]


@dataclass(frozen=True)
class Measured:
    """Why quality=auto chose its setting: the errors measured there, against what budget."""

    flip: float | None
    delta_e_p95: float | None
    basis: str
    max_flip: float | None = None
    max_delta_e: float | None = None


@dataclass(frozen=True)
class Tier:
    name: QualityName
    samples: int
    wavelengths: int  # the paper's rotation and the grating; a film's are below
    aa: AntiAliasName
    # K directional lights an environment becomes (bench/results/environment_lights.md,
    # 256², against K=256): each light costs about as much as the rest of the shading, and
    # ΔE00 mean falls from 2-4 (K=8) through 1-2.3 (16) and 0.6-1.6 (32) to 0.35-1 (64).
    environment_lights: int
    # Directions per pixel drawn from the material's lobe to read the environment map
    # (glsl/lib/environment_light.glsl), over all the tier's samples together. A film's,
    # below high, pooled over each 2×2 quad where its lobe is wider than a pixel's step:
    # against the brute-force reference (studio, 128², standard) 4 pooled measured FLIP
    # no higher than 6 unpooled on every film tried, 0.0185-0.073 against 0.0187-0.0815
    # (the bubble 0.040 against 0.050, oil-film 0.073 against 0.082), for two samples less.
    environment_samples: int
    # The same for the rotation source's three Ashikhmin-Shirley lobes (at draft and
    # standard a multiple of 3 a pass, so each lobe gets its third), pooled over each 2×2
    # quad of pixels where the lobe is wider than a pixel's step (ENV_QUAD_MEAN): against
    # the brute-force reference (studio, A-S 100×1000, θ 0.5/1.0, 128²) 3 left FLIP 0.111
    # and 6 0.086, where unpooled 3 left 0.128, 6 0.102 and 9 0.084
    # (bench/environment_accuracy.py).
    environment_samples_rotation: int
    # A grating's pieces of the curve its orders leave along, each read once
    # (glsl/lib/environment_grating.glsl), over all the tier's samples together: against
    # the same reads converged (bench/grating_environment.py, the grating presets, studio
    # and sky, 128²) 1 measured FLIP 0.065-0.066 in the studio, 2 0.046-0.049, 3 0.039; a
    # piece costs about a tenth of the key light at 256², and standard's 3 keep the tier
    # inside 1.5× it, draft's 1 inside 3× the floor, where 2 were 2.8-2.9× (bench/speed_env.py).
    environment_samples_grating: int
    # A thin film's wavelengths, per colour source's measured front: against an exact D65
    # reference (bench/white_point.py, ΔE00 mean / worst), on a dielectric the RGB fast
    # path (0) measured 0.10 / 1.5, 16 wavelengths 0.46 / 22 and 8 4.9 / 32 (thick films
    # alias into false colours); on a metal the fast path 1.6 / 12, 16 wavelengths
    # 0.37 / 7.0 and 8 3.2 / 35. Each tier takes the closest its cost allows. Over many
    # samples the wavelengths move from sample to sample, and 16 a sample leave colour noise
    # that 32 do not: at 8 samples (bench/accuracy.py, 128², every film preset and variant)
    # FLIP 0.0099-0.0268 with 16 against 0.0049-0.0151 with 32, every one lower, for
    # 1.14-1.3× the time under the key light and 1.5-1.9× in the studio (each of high's
    # map reads evaluates the film). On a dielectric high takes 32. On a metal it keeps 16:
    # the gain is smaller (0.010-0.020 to 0.007-0.013) and 32 took the metals in the studio
    # to 1.9-2.0× draft's time, past the 2× in which a tier must meet FLIP 0.05 (at their
    # own light, anodised-titanium's draft and standard do not).
    film_wavelengths: int
    metal_film_wavelengths: int
    # A stack of layers (film_stack_pairs > 0): its fast path integrates 16 bins, and its
    # narrow stop bands want more (the accuracy grid, 128², in the studio): at one sample
    # morpho 0.061 by the bins against 0.030 at 32 wavelengths, bragg-mirror 0.030 against
    # 0.015, for 1.0-1.05× the time where the map's light dominates.
    stack_wavelengths: int
    measured: Measured | None = None  # quality=auto only

    def wavelengths_for(self, material: Material | None) -> int:
        """The tier's wavelengths for ``material``'s colour source (the rotation's and the
        grating's without one)."""
        if material is None or material.iridescence != "thin-film":
            return self.wavelengths
        if material.film_stack_pairs > 0:
            return self.stack_wavelengths
        if material.substrate == "conductor":
            return self.metal_film_wavelengths
        return self.film_wavelengths

    def render_settings(self, material: Material | None = None) -> dict[str, int | str]:
        """The fields a request may override one by one, as the tier sets them for
        ``material`` (its wavelengths depend on the colour source)."""
        return {"samples": self.samples, "wavelengths": self.wavelengths_for(material),
                "aa": self.aa}

    def describe(self) -> dict[str, int | str]:
        """The tier as GET /v1/tiers and ``--help`` show it."""
        return {"name": self.name, **self.render_settings(),
                "film_wavelengths": self.film_wavelengths,
                "metal_film_wavelengths": self.metal_film_wavelengths,
                "stack_wavelengths": self.stack_wavelengths,
                "environment_lights": self.environment_lights,
                "environment_samples": self.environment_samples,
                "environment_samples_rotation": self.environment_samples_rotation,
                "environment_samples_grating": self.environment_samples_grating}


TIERS: dict[str, Tier] = {tier.name: tier for tier in (
    # Points on the measured fronts (docs/accuracy.md), one bundle for every preset. On most
    # presets the RGB model's own error outweighs one sample's aliasing, so the cheap tiers
    # buy wavelengths before samples: one sample of 8 wavelengths, band-limited, costs
    # little more than one RGB sample and has a third to half of its error.
    Tier("draft", samples=1, wavelengths=8, aa="analytic",
         environment_lights=8, environment_samples=2, environment_samples_rotation=3,
         environment_samples_grating=1, film_wavelengths=0, metal_film_wavelengths=0,
         stack_wavelengths=0),
    # FLIP <= 0.05 on every preset at about 1.5x draft's time.
    Tier("standard", samples=1, wavelengths=16, aa="analytic",
         environment_lights=16, environment_samples=4, environment_samples_rotation=6,
         environment_samples_grating=3, film_wavelengths=0, metal_film_wavelengths=16,
         stack_wavelengths=32),
    # FLIP <= 0.01 on the paper's presets; the wavelengths move between samples
    # (spectrum.py), 32 a sample on a film.
    Tier("high", samples=8, wavelengths=16, aa="none",
         environment_lights=32, environment_samples=64, environment_samples_rotation=64,
         environment_samples_grating=32, film_wavelengths=32, metal_film_wavelengths=16,
         stack_wavelengths=32),
    # The converged target: brute force, no analytic approximation; within FLIP 0.01 of twice
    # its samples and wavelengths even at theta = ±2π.
    Tier("reference", samples=64, wavelengths=32, aa="none",
         environment_lights=64, environment_samples=1024, environment_samples_rotation=1024,
         environment_samples_grating=512, film_wavelengths=32, metal_film_wavelengths=32,
         stack_wavelengths=32),
)}
if tuple(TIERS) != get_args(TierName):  # the Literal is what the schema and mypy read
    raise AssertionError(f"TierName {get_args(TierName)} does not list the tiers {tuple(TIERS)}")


def auto_tier(samples: int, wavelengths: int, aa: AntiAliasName, measured: Measured) -> Tier:
    """quality=auto's tier: the setting it picked, with the environment settings of the
    cheapest named tier that has at least its samples and wavelengths, and never below
    ``high``'s. The table measured the material under converged light (the reference
    tier's), so the light must not add its own error: against the brute-force reference
    (bench/results/environment_accuracy.md) lobe sampling is within FLIP 0.05 from high's
    64 samples on (0.001-0.044), 0.005-0.086 at standard's 4 (6 on the rotation's three
    lobes) and 0.005-0.111 at draft's 2 (3); a grating's reads, 0.079-0.13 at high."""
    like = next((tier for tier in TIERS.values()
                 if tier.samples >= samples and tier.wavelengths >= wavelengths),
                TIERS["reference"])
    high = TIERS["high"]
    return Tier("auto", samples, wavelengths, aa,
                max(like.environment_lights, high.environment_lights),
                max(like.environment_samples, high.environment_samples),
                max(like.environment_samples_rotation, high.environment_samples_rotation),
                max(like.environment_samples_grating, high.environment_samples_grating),
                wavelengths, wavelengths, wavelengths, measured)
