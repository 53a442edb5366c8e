"""A stack as the film in the shader (glsl/lib/thin_film_stack.glsl): its Rouard recursion
agrees with the float64 twin's characteristic matrix (model/stack_film.py) within the
stability suite's fp32 bound (test_physical_agreement.py's cases and bound), over random
stacks of 1-16 pairs (2-32 layers) on dielectrics and metals, weighted or whole, at the
fast path's own bins and 3, 16 and 32 wavelengths; and the extremes (32 layers, indices 1
and 3, thicknesses 0 and 2000 nm, grazing and degenerate geometry) stay finite."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model.material import MAX_STACK_PAIRS
from test_physical_agreement import cases_for, check, film_material

pytestmark = pytest.mark.gl


def stack_material(rng: np.random.Generator, substrate: str, **fixed):
    fields: dict = dict(substrate=substrate,
                        film_stack_pairs=int(rng.integers(1, MAX_STACK_PAIRS + 1)),
                        film_spacer_ior=float(rng.uniform(1.0, 3.0)),
                        film_spacer_thickness=float(rng.uniform(0.0, 2000.0)),
                        film_weight=float(rng.choice([1.0, rng.uniform(0.0, 1.0)])))
    if substrate == "conductor":
        fields["metal"] = str(rng.choice(["gold", "iron", "bismuth", "aluminium"]))
    return film_material(rng, **{**fields, **fixed})


@pytest.mark.parametrize("wavelengths", [0, 3, 16, 32])
@pytest.mark.parametrize("substrate", ["dielectric", "conductor"])
def test_stack_agrees_with_its_twin(renderer, substrate, wavelengths):
    rng = np.random.default_rng(2330 + wavelengths + (substrate == "conductor"))
    worst = 0.0
    for _ in range(10):
        material = stack_material(rng, substrate)
        worst = max(worst, check(renderer, material, cases_for(rng, material), wavelengths)[0])
    print(f"stack on {substrate}, {wavelengths} wavelengths: worst {worst:.3g} of the bound")


@pytest.mark.parametrize("film_ior,spacer_ior", [(1.0, 1.0), (3.0, 1.0), (1.0, 3.0), (3.0, 3.0)])
@pytest.mark.parametrize("thickness", [0.0, 2000.0])
def test_extremes_stay_within_the_bound(renderer, film_ior, spacer_ior, thickness):
    rng = np.random.default_rng(2340)
    for substrate in ("dielectric", "conductor"):
        material = stack_material(rng, substrate, film_stack_pairs=MAX_STACK_PAIRS,
                                  film_ior=film_ior, film_spacer_ior=spacer_ior,
                                  film_thickness_max=thickness,
                                  film_spacer_thickness=thickness, substrate_ior=4.0)
        _, gl = check(renderer, material, cases_for(rng, material), 16)
        assert np.isfinite(gl).all()
