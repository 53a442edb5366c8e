"""Feature defines and uniform values (opaline.gl.material_program): only what the material
uses, and the physical source over the paper's rules where both speak."""

from __future__ import annotations

import pytest

from opaline.gl import material_program
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
    plot = material_program.plot_defines(material, wavelengths, aa)
    full = material_program.material_defines(material, wavelengths, aa)
    assert full == {**plot, "DIFFUSE": full["DIFFUSE"], "FRESNEL": full["FRESNEL"]}
    assert set(plot) <= declared_defines("mdf_plot.glsl")
    assert set(full) <= declared_defines("surface.glsl")
    probe = material_program.material_defines(material, wavelengths)
    assert {k for k, v in probe.items() if v is not False} <= declared_defines("brdf_probe.glsl")


def test_features_follow_the_material():
    """One MDF at a time; diffuse only with kd > 0 and a non-black albedo; Fresnel only for f0 < 1;
    the analytic filter only on the multi-peak MDF."""
    assert material_program.material_defines(Material(), 0) == {
        "MDF_MULTIPEAK": True, "MDF_ASHIKHMIN": False, "WAVELENGTHS": False,
        "AA_ANALYTIC": False, "DIFFUSE": False, "FRESNEL": False,
    }
    assert material_program.material_defines(Material(kd=0.5, f0=0.04), 8)["WAVELENGTHS"] == 8
    assert material_program.material_defines(Material(kd=0.5, f0=0.04), 8)["DIFFUSE"]
    assert not material_program.material_defines(Material(kd=0.5, albedo=(0.0, 0.0, 0.0)))["DIFFUSE"]
    assert material_program.plot_defines(Material(), 0, "analytic")["AA_ANALYTIC"]
    assert not material_program.plot_defines(Material(mdf="ashikhmin"), 0, "analytic")["AA_ANALYTIC"]


def test_a_physical_source_wins_over_the_papers_rules():
    """Where the paper's rules and a physical source both set a define (the table in
    gl/material_program.py), the source's value is compiled: with the precedence reversed,
    a thin film on the multi-peak MDF with analytic AA and f0 < 1 would draw the peaks,
    filter them and put Schlick's Fresnel over the film's own Airy reflectance."""
    film = Material(iridescence="thin-film", mdf="multipeak", f0=0.04)
    defines = material_program.material_defines(film, 0, "analytic")
    assert defines["IRIDESCENCE_THIN_FILM"] and defines["MDF_ASHIKHMIN"]
    assert not (defines["MDF_MULTIPEAK"] or defines["AA_ANALYTIC"] or defines["FRESNEL"])
    # A grating keeps Schlick's term where f0 < 1 (its coating), and only there.
    assert material_program.material_defines(Material(iridescence="grating", f0=0.04))["FRESNEL"]
    assert not material_program.material_defines(Material(iridescence="grating"))["FRESNEL"]
    # The MDF plot draws the material's own mdf field: the paper's rule alone.
    assert material_program.plot_defines(film, 0, "analytic")["MDF_MULTIPEAK"]
