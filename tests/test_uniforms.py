"""Feature defines and uniform values (opaline.gl.uniforms): only what the material uses."""

from __future__ import annotations

import pytest

from opaline.gl import uniforms
from opaline.gl.shaders import declared_defines
from opaline.model.params import Material

MATERIALS = [
    Material(),
    Material(mdf="ashikhmin"),
    Material(kd=0.5, f0=0.04),
    Material(kd=0.5, albedo=(0.0, 0.0, 0.0)),
]


@pytest.mark.parametrize("material", MATERIALS, ids=lambda m: f"{m.mdf}-kd{m.kd}-f0{m.f0}")
@pytest.mark.parametrize("wavelengths", [0, 16])
@pytest.mark.parametrize("aa", ["none", "analytic"])
def test_each_program_declares_the_defines_it_is_given(material, wavelengths, aa):
    """The plot gets the MDF's defines, the surface all of them, the probe all but AA, and
    each program declares what it is given (the variant cache refuses anything else)."""
    plot = uniforms.mdf_defines(material, wavelengths, aa)
    full = uniforms.material_defines(material, wavelengths, aa)
    assert full == {**plot, "DIFFUSE": full["DIFFUSE"], "FRESNEL": full["FRESNEL"]}
    assert set(plot) <= declared_defines("mdf_plot.glsl")
    assert set(full) <= declared_defines("surface.glsl")
    probe = uniforms.material_defines(material, wavelengths)
    assert {k for k, v in probe.items() if v is not False} <= declared_defines("brdf_probe.glsl")


def test_features_follow_the_material():
    """One MDF at a time; diffuse only with kd > 0 and a non-black albedo; Fresnel only for f0 < 1;
    the analytic filter only on the multi-peak MDF."""
    assert uniforms.material_defines(Material(), 0) == {
        "MDF_MULTIPEAK": True, "MDF_ASHIKHMIN": False, "WAVELENGTHS": False,
        "AA_ANALYTIC": False, "DIFFUSE": False, "FRESNEL": False,
    }
    assert uniforms.material_defines(Material(kd=0.5, f0=0.04), 8)["WAVELENGTHS"] == 8
    assert uniforms.material_defines(Material(kd=0.5, f0=0.04), 8)["DIFFUSE"]
    assert not uniforms.material_defines(Material(kd=0.5, albedo=(0.0, 0.0, 0.0)))["DIFFUSE"]
    assert uniforms.mdf_defines(Material(), 0, "analytic")["AA_ANALYTIC"]
    assert not uniforms.mdf_defines(Material(mdf="ashikhmin"), 0, "analytic")["AA_ANALYTIC"]
