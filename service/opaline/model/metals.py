"""Complex refractive indices n + ik of conductor substrates (docs/physics.md §1.2).

A named metal reads the table shipped with the package (metals_nk.csv: published
measurements, each cited in the file's header, resampled to 380-780 nm every
10 nm), linearly interpolated in wavelength. ``metal = "artist"`` takes a
reflectance at normal incidence F0 and an edge tint per channel instead and maps
them to (n, k) as Gulbrandsen 2014 ("Artist friendly metallic Fresnel", JCGT
3(4)), the mapping OpenPBR and Arnold use; across the spectrum F0 and the tint
are interpolated between the channels' wavelengths and held beyond them.

The spectral paths read n + ik at each of their wavelengths; the RGB fast path one
index per channel: n + ik averaged over the channel's colour weight
(``visible.density_table``). Against the converged spectral path over films of
0-600 nm at v·h 0.05-1 that halves the mean error of taking the index at the
channel's centroid wavelength for gold (0.042 → 0.021 in linear RGB; copper 0.015
→ 0.012; flat metals such as titanium 0.003 either way); docs/physics.md §1.2.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from opaline.model import visible
from opaline.model.grating import channel_wavelengths
from opaline.model.spectrum import sample_wavelengths

if TYPE_CHECKING:
    from opaline.model.material import Material

TABLE_FILE = Path(__file__).with_name("metals_nk.csv")
# F0 at most 0.99 (silver's, about): Gulbrandsen's n = (1 + √r)/(1 - √r) has a pole at r = 1,
# and beyond 0.99 (n up to 4000 at tint 0) the reflectance near grazing hangs on v·h
# more finely than fp32 resolves it (tests/gl/test_physical_agreement.py, its ends).
F0_MAX = 0.99


@lru_cache(maxsize=1)
def table() -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(wavelengths in nm, {metal: n + ik at them})."""
    lines = [line for line in TABLE_FILE.read_text().splitlines() if not line.startswith("#")]
    names = lines[0].split(",")
    data = np.loadtxt(lines[1:], delimiter=",")
    metals = {names[i][:-2]: data[:, i] + 1j * data[:, i + 1] for i in range(1, len(names), 2)}
    return data[:, 0], metals


def metal_index(name: str, lam_nm: npt.ArrayLike) -> np.ndarray:
    """n + ik of a tabulated metal at ``lam_nm``."""
    grid, metals = table()
    nk = metals[name]
    lam = np.asarray(lam_nm, dtype=np.float64)
    index: np.ndarray = np.interp(lam, grid, nk.real) + 1j * np.interp(lam, grid, nk.imag)
    return index


def gulbrandsen(f0: npt.ArrayLike, tint: npt.ArrayLike) -> np.ndarray:
    """n + ik whose Fresnel reflectance is ``f0`` at normal incidence, with the edge
    tint ``tint`` (0: the n of least k, 1: the n of greatest), as Gulbrandsen 2014."""
    r = np.clip(np.asarray(f0, dtype=np.float64), 0.0, F0_MAX)
    g = np.clip(np.asarray(tint, dtype=np.float64), 0.0, 1.0)
    sqrt_r = np.sqrt(r)
    n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sqrt_r) / (1.0 - sqrt_r)
    k2 = (r * (n + 1.0) ** 2 - (n - 1.0) ** 2) / (1.0 - r)
    return n + 1j * np.sqrt(np.maximum(k2, 0.0))


def artist_index(f0: npt.ArrayLike, tint: npt.ArrayLike, lam_nm: npt.ArrayLike) -> np.ndarray:
    """Gulbrandsen's n + ik at ``lam_nm`` from per-channel (R, G, B) F0 and edge tint,
    each interpolated between the channels' wavelengths."""
    centres = channel_wavelengths()[::-1]  # increasing: B, G, R
    lam = np.asarray(lam_nm, dtype=np.float64)
    f0_at = np.interp(lam, centres, np.asarray(f0, dtype=np.float64)[::-1])
    tint_at = np.interp(lam, centres, np.asarray(tint, dtype=np.float64)[::-1])
    return gulbrandsen(f0_at, tint_at)


def substrate_index(material: Material, lam_nm: npt.ArrayLike) -> np.ndarray:
    """The material's conductor n + ik at ``lam_nm``."""
    if material.metal == "artist":
        return artist_index(material.metal_f0, material.metal_edge_tint, lam_nm)
    return metal_index(material.metal, lam_nm)


def substrate_for(material: Material, wavelengths: int) -> float | np.ndarray:
    """What the film's reference and shader take under the film: the dielectric's real
    index, or a conductor's n + ik at the path's wavelengths (the channels' for 0)."""
    if material.substrate != "conductor":
        return material.substrate_ior
    if wavelengths > 0:
        return substrate_index(material, sample_wavelengths(wavelengths))
    return channel_index(substrate_index(material, visible.density_table()[0]))


def channel_index(nk_on_grid: np.ndarray) -> np.ndarray:
    """Per channel (R, G, B): n + ik on the density table's grid averaged over the
    channel's colour weight."""
    density = visible.density_table()[1]
    averaged: np.ndarray = (density * nk_on_grid[:, None]).sum(axis=0) / density.sum(axis=0)
    return averaged


def bare_f0(nk: npt.ArrayLike) -> np.ndarray:
    """Fresnel reflectance at normal incidence from air, |(ñ - 1)/(ñ + 1)|²."""
    nk = np.asarray(nk)
    f0: np.ndarray = np.abs((nk - 1.0) / (nk + 1.0)) ** 2
    return f0
