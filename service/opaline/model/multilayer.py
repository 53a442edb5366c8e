"""Float64 reference of a multilayer stack (Bragg mirrors, dichroic coatings, Morpho-like
scales): reflectance and transmittance of any number of layers by the characteristic
(Abelès) matrix, both polarisations, absorbing media included.

Macleod, *Thin-Film Optical Filters* (5th ed.), §2.2-2.4, written for the n + ik
convention the project and colour-science use (Macleod's is n − ik: the matrix's i
changes sign): layer j of index Ñ_j = n + ik (k ≥ 0) and thickness d_j has the tilted
admittance η_s = q_j, η_p = Ñ_j²/q_j, with q_j = Ñ_j·cos θ_j = √(Ñ_j² − n₀² sin² θ₀) (the
root that decays into the layer, Im ≥ 0: evanescent beyond the critical angle, absorbed
in a metal), and phase thickness δ_j = 2π·q_j·d_j/λ. The stack's matrix is the product of

    M_j = [[cos δ_j, −i·sin δ_j / η_j], [−i·η_j·sin δ_j, cos δ_j]]

from the ambient down; [B, C] = Π M_j · [1, η_sub] gives

    r = (η₀·B − C)/(η₀·B + C),   R = |r|²,   T = 4·η₀·Re(η_sub)/|η₀·B + C|²

(η₀ real: the ambient is lossless). R + T = 1 for lossless layers, and T is 0 where
the substrate is evanescent (total internal reflection). This is the reference the
stack's shader is to be held to; no material field uses it yet (docs/physics.md).
``tests/model/test_multilayer.py`` holds it to colour-science's ``multilayer_tmm``, to the
single film's Airy sum, and to the quarter-wave stack's closed form.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

MAX_LAYERS = 32  # a stack's layers at most (the shader will unroll them)


@dataclass(frozen=True)
class StackOptics:
    """Per wavelength and angle (the inputs' broadcast shape): s and p reflectance and
    transmittance."""

    r_s: np.ndarray
    r_p: np.ndarray
    t_s: np.ndarray
    t_p: np.ndarray

    @property
    def reflectance(self) -> np.ndarray:
        """Unpolarised: the mean of s and p."""
        result: np.ndarray = 0.5 * (self.r_s + self.r_p)
        return result

    @property
    def transmittance(self) -> np.ndarray:
        result: np.ndarray = 0.5 * (self.t_s + self.t_p)
        return result


def _normal_component(index: np.ndarray, ambient: float, cos0: np.ndarray) -> np.ndarray:
    """q = Ñ·cos θ = √(Ñ² − (n₀ sin θ₀)²), the root with Im ≥ 0 (decaying into the medium),
    as √((Ñ² − n₀²) + n₀²·cos²θ₀): near grazing 1 − cos²θ₀ rounds to 1, which would make a
    layer of the ambient's index (n = 1 in air) reflect totally."""
    q = np.sqrt((index.astype(np.complex128) ** 2 - ambient**2) + (ambient * cos0) ** 2)
    result: np.ndarray = np.where(q.imag < 0.0, -q, q)
    return result


def stack_optics(layers: Sequence[complex | npt.ArrayLike], thicknesses_nm: npt.ArrayLike,
                 wavelength_nm: npt.ArrayLike,
                 cos0: npt.ArrayLike = 1.0, ambient: float = 1.0,
                 substrate: complex | npt.ArrayLike = 1.0) -> StackOptics:
    """R and T of ``layers`` (indices, the ambient's side first; each a number or one per
    wavelength along the last axis of ``wavelength_nm``'s shape) of ``thicknesses_nm``,
    between a lossless ``ambient`` and a ``substrate`` (a number or one per wavelength),
    lit at cos θ₀ = ``cos0``."""
    lam = np.asarray(wavelength_nm, dtype=np.float64)
    cos0 = np.asarray(cos0, dtype=np.float64)
    thicknesses = np.asarray(thicknesses_nm, dtype=np.float64)
    indices = [np.asarray(n, dtype=np.complex128) for n in layers]
    if len(indices) != len(thicknesses) or len(indices) > MAX_LAYERS:
        raise ValueError(f"{len(indices)} layers and {len(thicknesses)} thicknesses: one "
                         f"thickness a layer, at most {MAX_LAYERS} layers")
    eta0_s, eta0_p = ambient * cos0, ambient / np.maximum(cos0, 1e-300)
    q_sub = _normal_component(np.asarray(substrate), ambient, cos0)
    optics = {}
    for name, eta0 in (("s", eta0_s), ("p", eta0_p)):
        eta_sub = q_sub if name == "s" else np.asarray(substrate) ** 2 / q_sub
        b, c = np.ones_like(q_sub * lam), eta_sub * np.ones_like(lam)
        for index, d in zip(reversed(indices), reversed(thicknesses), strict=True):
            q = _normal_component(index, ambient, cos0)
            eta = q if name == "s" else index**2 / q
            delta = 2.0 * np.pi * q * d / lam
            cos_d, sin_d = np.cos(delta), np.sin(delta)
            b, c = cos_d * b - 1j * sin_d / eta * c, -1j * eta * sin_d * b + cos_d * c
        denominator = eta0 * b + c
        r = (eta0 * b - c) / denominator
        optics[name] = (np.abs(r) ** 2,
                        4.0 * eta0 * np.real(eta_sub) / np.abs(denominator) ** 2)
    return StackOptics(optics["s"][0], optics["p"][0], optics["s"][1], optics["p"][1])


def quarter_wave_peak(n_high: float, n_low: float, pairs: int, ambient: float = 1.0,
                      substrate: float = 1.0) -> float:
    """The closed form of (HL)^N at its design wavelength, at normal incidence, H on the
    ambient's side: each quarter-wave layer turns the admittance y below it into n²/y, so
    Y = (n_H/n_L)^(2N)·n_sub and R = ((n₀ − Y)/(n₀ + Y))²."""
    y = (n_high / n_low) ** (2 * pairs) * substrate
    return float(((ambient - y) / (ambient + y)) ** 2)
