"""The film's weight in the float64 reference (model/thinfilm.py, model/physical.py): KHR
iridescenceFactor's layering, mix(base, film, weight), with the base the bare substrate's
own Fresnel reflectance (a dielectric's, or the metal's), held against the textbook
Fresnel equations written out here."""

from __future__ import annotations

import numpy as np
import pytest

from opaline.model import metals, physical, thinfilm
from opaline.model.params import Material, MaterialFields
from opaline.model.reference import rgb_weights, shading_frame

COS1 = np.linspace(0.0, 1.0, 41)


def textbook_fresnel(cos1: np.ndarray, n_sub: complex | np.ndarray) -> np.ndarray:
    """Fresnel reflectance from air into ñ, s and p averaged; 1 at grazing."""
    c = np.asarray(cos1, dtype=np.complex128)
    n_cos = np.sqrt(n_sub * n_sub - 1.0 + c * c)
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = (c - n_cos) / (c + n_cos)
        rp = (n_sub * n_sub * c - n_cos) / (n_sub * n_sub * c + n_cos)
    r = 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)
    return np.where(np.real(c) > 0.0, r, 1.0)


def substrate(kind: str, wavelengths: int) -> float | np.ndarray:
    material = Material(iridescence="thin-film", substrate=kind, metal="gold",
                        substrate_ior=1.6)
    return metals.substrate_for(material, wavelengths)


@pytest.mark.parametrize("wavelengths", [0, 16, 128])
@pytest.mark.parametrize("kind", ["dielectric", "conductor"])
def test_weight_zero_is_the_bare_substrate(kind, wavelengths):
    n_sub = substrate(kind, wavelengths)
    got = thinfilm.film_layer_rgb(COS1, 420.0, 1.9, n_sub, 0.0, wavelengths)
    if kind == "dielectric":
        expected = np.repeat(textbook_fresnel(COS1, 1.6)[:, None], 3, axis=1)
    else:
        per = textbook_fresnel(COS1[:, None], np.asarray(n_sub)[None, :])
        expected = per @ rgb_weights(wavelengths) if wavelengths else per
    assert np.abs(got - expected).max() < 1e-12
    # ... which is also what a film of thickness 0 leaves (Airy's sum at φ = 0).
    assert np.abs(thinfilm.film_rgb(COS1, 0.0, 1.9, n_sub, wavelengths) - got).max() < 1e-12


@pytest.mark.parametrize("wavelengths", [0, 16])
@pytest.mark.parametrize("kind", ["dielectric", "conductor"])
def test_weight_mixes_base_and_film_linearly(kind, wavelengths):
    n_sub = substrate(kind, wavelengths)
    film = thinfilm.film_rgb(COS1, 420.0, 1.9, n_sub, wavelengths)
    base = thinfilm.film_base_rgb(COS1, n_sub, wavelengths)
    assert np.abs(film - base).max() > 0.05  # a film that shows
    for weight in (0.0, 0.5, 1.0):
        got = thinfilm.film_layer_rgb(COS1, 420.0, 1.9, n_sub, weight, wavelengths)
        assert np.abs(got - ((1.0 - weight) * base + weight * film)).max() < 1e-14


def test_specular_reads_the_weight():
    """physical.specular_thin_film is the lobe times the weighted colour."""
    n = np.array([[0.0, 0.0, 1.0]] * 3)
    frame = shading_frame(n, np.array([[1.0, 0.0, 0.0]] * 3))
    v = np.array([[0.6, 0.0, 0.8], [0.0, 0.3, np.sqrt(0.91)], [0.0, 0.0, 1.0]])
    l = v * [-1.0, -1.0, 1.0]
    half = Material(iridescence="thin-film", mdf="ashikhmin", film_weight=0.5)
    spec = {w: physical.specular_thin_film(half.model_copy(update={"film_weight": w}),
                                           frame, l, v) for w in (0.0, 0.5, 1.0)}
    assert np.allclose(spec[0.5], 0.5 * (spec[0.0] + spec[1.0]), rtol=1e-12, atol=0.0)
    assert np.abs(spec[1.0] - spec[0.0]).max() > 1e-3


@pytest.mark.parametrize("value", [-0.01, 1.01, float("nan")])
def test_weight_out_of_range_is_refused_naming_the_field(value):
    with pytest.raises(ValueError, match="film_weight"):
        MaterialFields.model_validate({"film_weight": value})
