r"""Gas: a fluid with the linear polynomial equation of state (ideal gas by
default), LS-DYNA's *MAT_NULL with *EOS_LINEAR_POLYNOMIAL or *EOS_IDEAL_GAS.

No deviatoric stress: :math:`\sigma = -pI`, with ``p`` from
:mod:`sphdyn.materials.eos.polynomial` (ideal gas: :math:`C_4 = C_5 = \gamma
- 1`, :math:`p = (\gamma - 1)\rho e`), cut at ``pressure_cutoff`` (<= 0), and
the energy equation of :func:`sphdyn.materials.fluid.fluid_energy`. The gas
starts at its initial density with the energy ``E0`` per unit initial volume,
or the one that gives the initial ``pressure``
(:math:`E_0 = (p_0 - C_0)/C_4`; ideal gas :math:`E_0 = p_0/(\gamma - 1)`).
Air at 1 atm: density 1.225 kg/m^3, gamma 1.4, pressure 101325 Pa.

The model and its tests: docs/theory.md, "Fluids: gas and high explosive".
"""

from __future__ import annotations

from typing import Literal, Optional

import numpy as np
from numba import njit, prange
from pydantic import Field, model_validator

from ..deck.messages import problem
from ..deck.sections.material import MaterialSection
from ..deck.units import PRESSURE
from ..deck.values import quantity, real
from .base import (P_DENSITY, MaterialModel, get_float, isotropic6, load_sym6, register,
                   store_sym6, trace6)
from .registry import schema_defaults
from .eos.polynomial import polynomial_parts, polynomial_pressure, polynomial_sound_speed
from .fluid import fluid_energy

# parameter vector after the common [density, K, G]: C0..C6, cutoff, E0
P_C0, P_PMIN, P_E0 = 3, 10, 11
POLY_KEYS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6")


@njit(cache=True, error_model="numpy", parallel=True)
def gas_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the gas (common kernel signature): for each ``i`` in
    ``idx`` the pressure ``a + b e`` of the polynomial EOS at ``mu = rho/rho0 -
    1`` (``b = rho0 (C4 + C5 mu + C6 mu^2)``) and the energy of
    :func:`~sphdyn.materials.fluid.fluid_energy`; ``sig = -p I``; ``c`` the
    isentropic sound speed. ``damage``, ``hist``, ``size`` are not used.
    Shapes/units: ``base.KERNEL_SIGNATURE_DOC``."""
    rho0 = params[P_DENSITY]
    C0, C1, C2, C3 = params[P_C0], params[P_C0 + 1], params[P_C0 + 2], params[P_C0 + 3]
    C4, C5, C6 = params[P_C0 + 4], params[P_C0 + 5], params[P_C0 + 6]
    p_min = params[P_PMIN]
    for k in prange(idx.shape[0]):
        i = idx[k]
        mu = rho[i] / rho0 - 1.0
        a, b, _, _ = polynomial_parts(mu, C0, C1, C2, C3, C4, C5, C6)
        tr_d = L[i, 0, 0] + L[i, 1, 1] + L[i, 2, 2]
        p_old = -trace6(load_sym6(sig, i)) / 3.0
        e_new, p = fluid_energy(e[i], 0.0, p_old, a, rho0 * b, p_min, tr_d, dt, rho[i])
        e[i] = e_new
        store_sym6(sig, i, isotropic6(-p))
        c[i] = polynomial_sound_speed(rho[i], rho0, rho0 * e_new, C0, C1, C2, C3, C4, C5,
                                      C6)


class GasParams(MaterialSection):
    """[[material]] model = "gas": a fluid with no strength, ideal gas or
    linear polynomial equation of state (air, water)."""

    model: Literal["gas"] = Field(description="Constitutive model.")
    eos: Literal["ideal_gas", "linear_polynomial"] = Field(
        "ideal_gas", description="Equation of state: ideal_gas p = (gamma - 1) rho e; "
        "linear_polynomial p = C0 + C1 mu + C2 mu^2 + C3 mu^3 + (C4 + C5 mu + C6 mu^2) E "
        "(mu = rho/rho0 - 1, E = rho0 e; C2, C6 only in compression).")
    gamma: Optional[real("gamma", lo=1, lo_open=True)] = Field(
        None, description="Ratio of specific heats of the ideal gas (1.4 if absent).")
    C0: Optional[quantity(PRESSURE, "C0")] = Field(None, description="Polynomial C0.")
    C1: Optional[quantity(PRESSURE, "C1")] = Field(None, description="Polynomial C1.")
    C2: Optional[quantity(PRESSURE, "C2")] = Field(None, description="Polynomial C2.")
    C3: Optional[quantity(PRESSURE, "C3")] = Field(None, description="Polynomial C3.")
    C4: Optional[real("C4")] = Field(None, description="Polynomial C4.")
    C5: Optional[real("C5")] = Field(None, description="Polynomial C5.")
    C6: Optional[real("C6")] = Field(None, description="Polynomial C6.")
    pressure: Optional[quantity(PRESSURE, "initial pressure", lo=0)] = Field(
        None, description="Initial pressure (sets E0); give this or E0 (neither: 0).")
    E0: Optional[quantity(PRESSURE, "initial energy", lo=0)] = Field(
        None, description="Initial internal energy per unit initial volume.")
    pressure_cutoff: quantity(PRESSURE, "pressure cutoff", hi=0) = Field(
        0.0, description="Lowest pressure the gas takes (tension negative).")
    min_density_factor: real("minimum density factor", lo=0, hi=1, hi_open=True) = Field(
        1e-3, description="As for every material; a gas expands freely.")
    max_density_factor: real("maximum density factor", lo=1, lo_open=True) = Field(
        20.0, description="As for every material; a strong shock compresses an ideal "
                          "gas (gamma + 1)/(gamma - 1) times (6 for air), a reflected "
                          "one about 20 times.")

    @model_validator(mode="after")
    def _one_eos(self):
        given = [k for k in POLY_KEYS if getattr(self, k) is not None]
        if self.eos == "ideal_gas" and given:
            raise problem(f"{', '.join(given)} belong to the linear polynomial EOS but "
                          "eos = \"ideal_gas\"", "remove them, or set eos = "
                          "\"linear_polynomial\"")
        if self.eos == "linear_polynomial" and self.gamma is not None:
            raise problem("gamma belongs to the ideal gas but eos = \"linear_polynomial\"",
                          "give C4 and C5 equal to gamma - 1 instead, or set eos = "
                          "\"ideal_gas\"")
        if self.pressure is not None and self.E0 is not None:
            raise problem("both pressure and E0 are given (each sets the other)",
                          "give one of them")
        if self.pressure is not None and self.eos == "linear_polynomial" \
                and not self.C4 and self.pressure != (self.C0 or 0.0):
            raise problem("the initial pressure cannot be reached: C4 is 0, so the "
                          "energy does not change the pressure at rest (p = C0)",
                          "give E0, or C4 > 0")
        return self


def _coefficients(values: dict) -> list[float]:
    if values.get("eos", "ideal_gas") == "ideal_gas":
        g = get_float(values, "gamma", default=1.4, min_value=1.0, min_inclusive=False)
        return [0.0, 0.0, 0.0, 0.0, g - 1.0, g - 1.0, 0.0]
    return [get_float(values, k, default=0.0) for k in POLY_KEYS]


def pack_gas(values: dict) -> np.ndarray:
    """``[density, K, 0, C0..C6, pressure_cutoff, E0]`` from SI values; ``K =
    rho0 c0^2`` at the initial state (a floor of 1 Pa for a gas at rest with no
    energy, whose sound speed is 0)."""
    rho0 = get_float(values, "density", min_value=0.0, min_inclusive=False)
    C = _coefficients(values)
    if values.get("pressure") is not None:
        p0 = get_float(values, "pressure", min_value=0.0)
        if p0 != C[0] and C[4] == 0.0:
            raise ValueError("the initial pressure cannot be reached with C4 = 0")
        E0 = 0.0 if p0 == C[0] else (p0 - C[0]) / C[4]
    else:
        E0 = get_float(values, "E0", default=0.0, min_value=0.0)
    p_min = get_float(values, "pressure_cutoff",
                      default=schema_defaults(GasParams)["pressure_cutoff"], max_value=0.0)
    c0 = float(polynomial_sound_speed(rho0, rho0, E0, *C))
    return np.array([rho0, max(rho0 * c0 * c0, 1.0), 0.0, *C, p_min, E0])


def initial_gas_state(params: np.ndarray) -> tuple[float, float]:
    """``(e0 [J/kg], p0 [Pa])`` at rest at the initial density: ``E0 / rho0`` and
    the pressure at ``mu = 0`` (``C0 + C4 E0``), not below the cutoff."""
    E0 = float(params[P_E0])
    p0 = polynomial_pressure(0.0, E0, *params[P_C0:P_C0 + 7])
    return E0 / params[P_DENSITY], max(float(p0), float(params[P_PMIN]))


GAS = register(MaterialModel(
    name="gas",
    history_names=(),
    pack=pack_gas,
    update=gas_update,
    schema=GasParams,
    fluid=True,
    initial_state=initial_gas_state,
    test_density=None,
))

__all__ = ["GAS", "GasParams", "gas_update", "initial_gas_state", "pack_gas"]
