"""The clear coat's float64 twin (model/coat.py) against closed forms: the layering of
KHR_materials_clearcoat written out here independently, the coat alone in mirror
geometry, its albedo against Schlick's Fresnel, and the roughness mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from opaline.model import coat
from opaline.model import reference as ref
from opaline.model.params import Material

Z, X = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])


def mirror(cos_theta: float) -> tuple[np.ndarray, np.ndarray]:
    """l and v mirrored about n = z: h = n, v·h = n·v = n·l = ``cos_theta``."""
    s = math.sqrt(1.0 - cos_theta**2)
    return np.array([-s, 0.0, cos_theta]), np.array([s, 0.0, cos_theta])


def schlick(f0: float, c: float) -> float:
    return f0 + (1.0 - f0) * (1.0 - c) ** 5


@pytest.mark.parametrize("cos_theta", [1.0, 0.7, 0.2, 0.02])
@pytest.mark.parametrize("weight,roughness,ior", [(1.0, 0.0, 1.5), (0.5, 0.3, 2.2)])
def test_a_coat_over_nothing_is_its_own_lobe(cos_theta, weight, roughness, ior):
    """ks = kd = 0: what is left is w·D(n)·F(cos θ)/(4 cos²θ)·cos θ, D(n) = (e+1)/(2π)."""
    material = Material(mdf="ashikhmin", ks=0.0, kd=0.0, coat_weight=weight,
                        coat_roughness=roughness, coat_ior=ior)
    l, v = mirror(cos_theta)
    e = 2.0 / max(roughness, 0.02) ** 4 - 2.0
    e = min(e, 1e6)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    expected = (weight * (e + 1.0) / (2.0 * math.pi) * schlick(f0, cos_theta)
                / (4.0 * max(cos_theta, 1e-4) ** 2) * cos_theta)
    found = ref.reflected_radiance(material, Z, X, l, v)
    np.testing.assert_allclose(found, expected, rtol=1e-12)


def test_the_base_is_dimmed_by_the_coats_fresnel_toward_the_view():
    """f = f_base·(1 − w·F(n·v)) + coat: n·v, not v·h, as KHR and the Sample Viewer."""
    base = Material(mdf="ashikhmin", ex=30.0, ey=30.0, kd=0.3, f0=0.2)
    coated = base.model_copy(update={"coat_weight": 0.8, "coat_roughness": 0.5,
                                     "coat_ior": 1.8})
    rng = np.random.default_rng(5)
    l = rng.normal(size=(64, 3))
    v = rng.normal(size=(64, 3))
    l[:, 2], v[:, 2] = np.abs(l[:, 2]), np.abs(v[:, 2])
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    f0 = (0.8 / 2.8) ** 2
    keep = 1.0 - 0.8 * (f0 + (1.0 - f0) * (1.0 - v[:, 2]) ** 5)
    frame = (np.tile(X, (64, 1)), np.tile([0.0, 1.0, 0.0], (64, 1)), np.tile(Z, (64, 1)))
    lobe = coat.coat_specular(coated, frame, l, v) * np.maximum(l[:, 2], 0.0)
    expected = ref.reflected_radiance(base, Z, X, l, v) * keep[:, None] + lobe[:, None]
    np.testing.assert_allclose(ref.reflected_radiance(coated, Z, X, l, v), expected,
                               rtol=1e-12, atol=1e-15)
    assert (lobe > 0).any()


def test_no_coat_changes_nothing():
    plain = Material(mdf="ashikhmin")
    l, v = mirror(0.6)
    weightless = plain.model_copy(update={"coat_roughness": 0.7, "coat_ior": 3.0})
    assert np.array_equal(ref.reflected_radiance(plain, Z, X, l, v),
                          ref.reflected_radiance(weightless, Z, X, l, v))


@pytest.mark.parametrize("cos_v", [1.0, 0.8, 0.5, 0.3])
def test_a_sharp_coats_albedo_is_its_fresnel(cos_v):
    """A mirror coat reflects F(n·v) of a white surround (what the shader's one read a
    pass converges to); a rough one never more than 1."""
    sharp = Material(coat_weight=1.0, coat_roughness=0.0)
    # (within the Fresnel curve's change across the lobe: 0.3 % at n·v = 0.3)
    assert coat.coat_albedo(sharp, cos_v) == pytest.approx(schlick(0.04, cos_v), rel=5e-3)
    rough = Material(coat_weight=1.0, coat_roughness=1.0, coat_ior=3.0)
    assert 0.0 < coat.coat_albedo(rough, cos_v) <= 1.0


def test_roughness_maps_to_the_exponent_of_the_same_ggx_width():
    """n = 2/r⁴ − 2 (glTF's α = r², Walter et al.'s n = 2/α² − 2), and back."""
    assert coat.exponent_from_roughness(0.1) == pytest.approx(19998.0)
    assert coat.exponent_from_roughness(1.0) == 0.0
    assert coat.exponent_from_roughness(0.0) == 1e6  # clamped to 0.02, then to the range
    for r in (0.05, 0.2, 0.6, 1.0):
        assert coat.roughness_from_exponent(coat.exponent_from_roughness(r)) == pytest.approx(r)


@pytest.mark.parametrize("field,value", [("coat_weight", 1.01), ("coat_weight", -0.1),
                                         ("coat_roughness", 2.0), ("coat_ior", 0.9),
                                         ("coat_ior", 3.5)])
def test_out_of_range_coat_fields_are_refused_by_name(field, value):
    with pytest.raises(ValidationError, match=field):
        Material(**{field: value})
