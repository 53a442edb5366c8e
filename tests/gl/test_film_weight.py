"""The film's weight (KHR iridescenceFactor) in the shader: its GLSL (film_layer_rgb,
film_base_rgb in glsl/lib/thin_film*.glsl) agrees with the float64 twin
(model/thinfilm.py) at weights 0, 0.5 and 1, over a dielectric and a metal, on the fast
and the spectral path, within the stability suite's fp32 bound (the bound and the cases
of test_physical_agreement.py); and at weight 0 the shader draws the bare substrate:
the paper's lobe with the exact Fresnel reflectance of the substrate (or the metal) in
place of the film's.
"""

from __future__ import annotations

import numpy as np
import pytest

from opaline.gl import material_program
from opaline.model import metals
from opaline.model import reference as ref
from opaline.model.params import Material
from test_physical_agreement import METALS, cases_for, check, film_material

pytestmark = pytest.mark.gl


def weighted_material(rng: np.random.Generator, weight: float, substrate: str) -> Material:
    fields: dict = {"film_weight": weight, "substrate": substrate}
    if substrate == "conductor":
        fields.update(metal=str(rng.choice(METALS)),
                      metal_f0=tuple(float(x) for x in rng.uniform(0.0, 1.0, 3)),
                      metal_edge_tint=tuple(float(x) for x in rng.uniform(0.0, 1.0, 3)))
    return film_material(rng, **fields)


@pytest.mark.parametrize("wavelengths", [0, 16])
@pytest.mark.parametrize("substrate", ["dielectric", "conductor"])
@pytest.mark.parametrize("weight", [0.0, 0.5, 1.0])
def test_weighted_film_agrees_with_its_twin(renderer, weight, substrate, wavelengths):
    rng = np.random.default_rng(2300 + int(10 * weight) + wavelengths)
    worst = 0.0
    for _ in range(12):
        material = weighted_material(rng, weight, substrate)
        worst = max(worst, check(renderer, material, cases_for(rng, material), wavelengths)[0])
    print(f"weight {weight} on {substrate}, {wavelengths} wavelengths: worst {worst:.3g} "
          "of the bound")


def mirror_cases(cos_values: np.ndarray):
    """Light and view mirrored about n (h = n), so v·h = n·v = ``cos_values``."""
    angles = np.arccos(cos_values)
    v = np.stack([np.sin(angles), 0.0 * angles, np.cos(angles)], axis=1)
    n = np.tile([0.0, 0.0, 1.0], (len(angles), 1))
    t = np.tile([1.0, 0.0, 0.0], (len(angles), 1))
    return n, t, v * [-1.0, 1.0, 1.0], v


def bare_fresnel(cos1: np.ndarray, n_sub: complex | np.ndarray) -> np.ndarray:
    """Textbook Fresnel reflectance from air into ñ, s and p averaged (Born & Wolf)."""
    cos1 = np.asarray(cos1, dtype=np.complex128)
    n_cos = np.sqrt(n_sub * n_sub - 1.0 + cos1 * cos1)
    rs = (cos1 - n_cos) / (cos1 + n_cos)
    rp = (n_sub * n_sub * cos1 - n_cos) / (n_sub * n_sub * cos1 + n_cos)
    return np.real(0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2))


@pytest.mark.parametrize("wavelengths", [0, 32])
@pytest.mark.parametrize("substrate", ["dielectric", "conductor"])
def test_weight_zero_draws_the_bare_substrate(renderer, substrate, wavelengths):
    """Mirror geometry, where the lobe's factor is known in closed form: the shader's
    radiance over ks·D/(4·cos²θ)·cos θ is the substrate's own Fresnel reflectance, the film
    (thick and coloured here) gone; with weight 1 it is not (the film is there)."""
    material = Material(iridescence="thin-film", mdf="ashikhmin", ex=10.0, ey=10.0,
                        film_ior=2.0, substrate_ior=1.7, film_thickness_max=350.0,
                        substrate=substrate, metal="copper", film_weight=0.0)
    cos1 = np.array([1.0, 0.9, 0.7, 0.5, 0.3, 0.15])
    n, t, l, v = mirror_cases(cos1)
    gl = renderer.probe(material, n, t, l, v, wavelengths)
    lobe = ref.mdf_ashikhmin(0.0, 0.0, 1.0, 10.0, 10.0) / (4.0 * cos1 * cos1) * cos1
    if substrate == "dielectric":
        expected = np.repeat(bare_fresnel(cos1, 1.7)[:, None], 3, axis=1)
    else:
        nk = metals.substrate_for(material, wavelengths)
        per = bare_fresnel(cos1[:, None], np.asarray(nk)[None, :])
        expected = per @ ref.rgb_weights(wavelengths) if wavelengths else per
    assert np.allclose(gl / lobe[:, None], expected, rtol=2e-4, atol=1e-6)
    whole = renderer.probe(material.model_copy(update={"film_weight": 1.0}), n, t, l, v,
                           wavelengths)
    assert np.abs(whole / lobe[:, None] - expected).max() > 0.05


def test_the_base_is_compiled_in_only_for_a_partial_film():
    """A whole film (the default, and every preset) compiles as before the weight: no
    FILM_WEIGHT define, so neither the base's Fresnel nor the mix is in its shader."""
    whole = material_program.material_defines(Material(iridescence="thin-film"))
    partial = material_program.material_defines(Material(iridescence="thin-film",
                                                         film_weight=0.5))
    assert "FILM_WEIGHT" not in whole
    assert partial["FILM_WEIGHT"] is True
    assert "FILM_WEIGHT" not in material_program.material_defines(Material(film_weight=0.5))
