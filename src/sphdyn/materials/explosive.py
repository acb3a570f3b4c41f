r"""High explosive: JWL detonation products lit by a programmed or beta burn.

The material of LS-DYNA's *MAT_HIGH_EXPLOSIVE_BURN with *EOS_JWL, in SPH.
No deviatoric strength: :math:`\sigma = -pI`. Each particle carries a burn
fraction :math:`F \in [0, 1]` that never decreases,

.. math::
    F = \min\big(1, \max(F^{n}, F_1, F_2)\big), \qquad
    F_1 = \frac{(t - t_l)\,D}{w_b\, s}\ (t > t_l), \qquad
    F_2 = \frac{1 - V}{1 - V_{CJ}},

with :math:`t_l` the particle's lighting time (the straight-line distance
from the nearest detonation point over ``D``, plus that point's time,
:mod:`sphdyn.build.detonation`), ``s`` the particle size (its initial spacing),
:math:`w_b` the burn width in particle sizes (1.5: LS-DYNA's
:math:`F_1 = 2(t - t_l) D A_{max} / (3 v)` for a cube of side ``s``), and
:math:`V_{CJ} = 1 - p_{CJ} / (\rho_0 D^2)` (the Rayleigh line). ``burn``
chooses :math:`F_1` (programmed), :math:`F_2` (beta) or the larger (both,
the default; LS-DYNA's BETA = 2, 1, 0). The unburned explosive has no
stiffness (``p = 0`` at ``F = 0``). With the programmed burn alone a front
run over many particles overdrives (1D TNT at 1600 particles per 0.1 m:
49 GPa after 8 us, 400 particles stay near P_CJ): the kernel reaches ahead
of the front, the burned particles compress the unlit ones before their
lighting time, and those burn at a smaller relative volume, so at a higher
pressure, which compresses the next ones more; the front's speed is fixed,
so nothing relaxes it (measured: the relative volume at the lighting time
falls from 0.89 at 25 mm to 0.84 at 50 mm and 0.62 at 55 mm, the peak
pressure from 21 to 28 and 49 GPa; a stiffness of the unburned explosive
slows this but does not stop it). With the beta part a compressed particle
burns as soon as it is compressed, and the front stays at the
Chapman-Jouguet state (relative volume at lighting 0.84-0.87, 21.7 GPa at
8 us, 22.4 GPa at 12 us).

Energy. The particle starts with no internal energy; as it burns, the
chemical energy :math:`q = E_0/\rho_0` per unit mass is released into it,
:math:`\Delta e = (F^{n+1} - F^n)\, q`, so the energy released is the burned
mass times :math:`E_0/\rho_0` and the energy balance counts it as supplied
(``E_chemical``, :attr:`MaterialModel.released_energy`). Pressure

.. math:: p = F\,p_c(V) + \omega\rho e

(:mod:`sphdyn.materials.eos.jwl`; with :math:`e = Fq` before any work this is
LS-DYNA's :math:`p = F\,p_{JWL}(V, E_0)`), cut at ``pressure_cutoff``
(<= 0, a fluid takes no tension). The sound speed is that of the fully
burned products at the particle's state (the unburned part's energy
included), so the time step is already the one the burn will need.

References: Lee, Hornig & Kury (1968), UCRL-50422 (JWL); LS-DYNA Keyword
User's Manual vol. II, *MAT_HIGH_EXPLOSIVE_BURN; Dobratz & Crawford (1985),
LLNL Explosives Handbook, UCRL-52997 (the TNT constants).

The model and its tests: docs/theory.md, "Fluids: gas and high explosive".
"""

from __future__ import annotations

from typing import Literal, Optional

import numpy as np
from numba import njit, prange
from pydantic import Field, model_validator

from ..deck.messages import problem
from ..deck.sections.material import Density, MaterialSection
from ..deck.units import PRESSURE, VELOCITY
from ..deck.values import PositivePressure, quantity, real
from .base import (P_DENSITY, MaterialModel, get_float, isotropic6, load_sym6, register,
                   store_sym6, trace6)
from .registry import schema_defaults
from .eos.jwl import jwl_parts, jwl_sound_speed
from .fluid import fluid_energy

#: TNT (Dobratz & Crawford 1985; the issue's and LS-DYNA's common set), SI.
TNT = {"density": 1630.0, "D": 6930.0, "P_CJ": 21.0e9, "A": 371.2e9, "B": 3.231e9,
       "R1": 4.15, "R2": 0.95, "omega": 0.30, "E0": 7.0e9}
PRESETS = {"tnt": TNT}

BURN_MODES = {"programmed": 0, "beta": 1, "both": 2}

# parameter vector after the common [density, K, G]
P_A, P_B, P_R1, P_R2, P_W, P_E0, P_D, P_PCJ, P_VCJ, P_MODE, P_WIDTH, P_PMIN = range(3, 15)
#: history columns
H_BURN, H_CLOCK = 0, 1
#: the burn clock t - t_l of a particle no detonation point lights
UNLIT = -1e30


@njit(cache=True, error_model="numpy")
def burn_fraction(f_old, clock, V, size, D, V_cj, width, mode):
    """Burn fraction after a step (module docstring): ``clock = t - t_l`` [s],
    ``V`` relative volume, ``size`` particle size [m], ``D`` detonation
    velocity [m/s], ``V_cj``, ``width`` burn width in sizes, ``mode`` 0
    programmed, 1 beta, 2 both."""
    f = f_old
    if mode != 1 and clock > 0.0:
        f = max(f, clock * D / (width * size))
    if mode != 0:
        f = max(f, (1.0 - V) / (1.0 - V_cj))
    return min(f, 1.0)


@njit(cache=True, error_model="numpy", parallel=True)
def explosive_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the high explosive (common kernel signature).

    For each ``i`` in ``idx``: the burn clock ``hist[i, 1] += dt`` (it starts
    at minus the lighting time), the burn fraction ``hist[i, 0]``
    (:func:`burn_fraction`), the released energy, the pressure and energy of
    :func:`sphdyn.materials.fluid.fluid_energy` with ``a = F p_c(V)``,
    ``b = omega rho``; ``sig = -p I``; ``c`` the fully burned products' sound
    speed. ``damage`` is not used. Shapes/units: ``base.KERNEL_SIGNATURE_DOC``.
    """
    rho0 = params[P_DENSITY]
    A, B, R1, R2, w = params[P_A], params[P_B], params[P_R1], params[P_R2], params[P_W]
    q = params[P_E0] / rho0
    D, V_cj, width = params[P_D], params[P_VCJ], params[P_WIDTH]
    mode = int(params[P_MODE])
    p_min = params[P_PMIN]
    for k in prange(idx.shape[0]):
        i = idx[k]
        clock = hist[i, H_CLOCK] + dt
        hist[i, H_CLOCK] = clock
        V = rho0 / rho[i]
        f_old = hist[i, H_BURN]
        f = burn_fraction(f_old, clock, V, size[i], D, V_cj, width, mode)
        hist[i, H_BURN] = f
        pc, _ = jwl_parts(V, A, B, R1, R2, w)
        tr_d = L[i, 0, 0] + L[i, 1, 1] + L[i, 2, 2]
        p_old = -trace6(load_sym6(sig, i)) / 3.0
        e_new, p = fluid_energy(e[i], (f - f_old) * q, p_old, f * pc, w * rho[i], p_min,
                                tr_d, dt, rho[i])
        e[i] = e_new
        store_sym6(sig, i, isotropic6(-p))
        c[i] = jwl_sound_speed(rho[i], V, rho0 * (e_new + (1.0 - f) * q), A, B, R1, R2, w)


class ExplosiveParams(MaterialSection):
    """[[material]] model = "high_explosive": JWL products with a programmed or
    beta burn (LS-DYNA's *MAT_HIGH_EXPLOSIVE_BURN and *EOS_JWL).

    Give ``preset = "tnt"`` and override any key, or give every key. The
    charge is lit by the [[detonation]] points.
    """

    model: Literal["high_explosive"] = Field(description="Constitutive model.")
    preset: Optional[Literal["tnt"]] = Field(
        None, description="Constants of a known explosive; keys given beside it "
        "override it one by one. tnt: density 1630 kg/m^3, D 6930 m/s, P_CJ 21 GPa, "
        "A 371.2 GPa, B 3.231 GPa, R1 4.15, R2 0.95, omega 0.30, E0 7.0 GPa "
        "(Dobratz & Crawford 1985).")
    density: Optional[Density] = Field(
        None, description="Initial (unreacted) density rho0 (from the preset if absent).")
    D: Optional[quantity(VELOCITY, "detonation velocity", lo=0, lo_open=True)] = Field(
        None, description="Detonation velocity: lighting times and the programmed burn.")
    P_CJ: Optional[PositivePressure] = Field(
        None, description="Chapman-Jouguet pressure: V_CJ = 1 - P_CJ/(rho0 D^2) of the "
                          "beta burn.")
    A: Optional[PositivePressure] = Field(None, description="JWL constant A.")
    B: Optional[PositivePressure] = Field(None, description="JWL constant B.")
    R1: Optional[real("JWL R1", lo=0, lo_open=True)] = Field(
        None, description="JWL constant R1.")
    R2: Optional[real("JWL R2", lo=0, lo_open=True)] = Field(
        None, description="JWL constant R2.")
    omega: Optional[real("JWL omega", lo=0, lo_open=True)] = Field(
        None, description="JWL constant omega (Grueneisen coefficient of the products).")
    E0: Optional[PositivePressure] = Field(
        None, description="Chemical energy per unit initial volume, released as the "
                          "explosive burns (E0 / rho0 per unit mass).")
    burn: Literal["programmed", "beta", "both"] = Field(
        "both", description="Burn fraction from the lighting time (programmed), "
        "from the compression (beta: (1 - V)/(1 - V_CJ)) or the larger of the two "
        "(both, LS-DYNA's default); LS-DYNA's BETA = 2, 1, 0. With programmed "
        "alone a front run over many particles overdrives: the kernel compresses the "
        "unlit explosive ahead of it (docs/theory.md).")
    burn_width: real("burn width", lo=0, lo_open=True) = Field(
        1.5, description="Width of the programmed burn front in particle spacings "
                         "(1.5 is LS-DYNA's 2 A_max / (3 v) for a cube).")
    pressure_cutoff: quantity(PRESSURE, "pressure cutoff", hi=0) = Field(
        0.0, description="Lowest pressure the products take (tension negative; 0: "
                         "none).")
    min_density_factor: real("minimum density factor", lo=0, hi=1, hi_open=True) = Field(
        1e-3, description="As for every material; products expand a thousandfold.")
    max_density_factor: real("maximum density factor", lo=1, lo_open=True) = Field(
        5.0, description="As for every material.")

    @model_validator(mode="before")
    @classmethod
    def _preset(cls, data):
        if isinstance(data, dict) and data.get("preset") in PRESETS:
            return {**PRESETS[data["preset"]], **data}
        return data

    @model_validator(mode="after")
    def _complete(self):
        missing = [k for k in TNT if getattr(self, k) is None]
        if missing:
            raise problem(f"the explosive has no {', '.join(missing)}",
                          "give them, or preset = \"tnt\" and override keys one by one")
        return self


def pack_explosive(values: dict) -> np.ndarray:
    """``[density, K, 0, A, B, R1, R2, omega, E0, D, P_CJ, V_CJ, mode, burn_width,
    pressure_cutoff]`` from SI values (a preset filled in); ``K = rho0 c^2`` of
    the fully burned products at the initial density."""
    values = {**PRESETS.get(values.get("preset"), {}), **values}
    g = {k: get_float(values, k, min_value=0.0, min_inclusive=False)
         for k in ("density", "A", "B", "R1", "R2", "omega", "E0", "D", "P_CJ")}
    rho0 = g["density"]
    v_cj = 1.0 - g["P_CJ"] / (rho0 * g["D"] ** 2)
    if v_cj <= 0.0:
        raise ValueError(f"P_CJ = {g['P_CJ']:.4g} Pa is not below rho0 D^2 = "
                         f"{rho0 * g['D'] ** 2:.4g} Pa (V_CJ would be <= 0; TNT: 21 GPa, "
                         "6930 m/s, 1630 kg/m^3)")
    c0 = float(jwl_sound_speed(rho0, 1.0, g["E0"], g["A"], g["B"], g["R1"], g["R2"],
                               g["omega"]))
    default = schema_defaults(ExplosiveParams)
    width = get_float(values, "burn_width", default=default["burn_width"], min_value=0.0,
                      min_inclusive=False)
    p_min = get_float(values, "pressure_cutoff", default=default["pressure_cutoff"],
                      max_value=0.0)
    mode = BURN_MODES[values.get("burn", default["burn"])]
    return np.array([rho0, rho0 * c0 * c0, 0.0, g["A"], g["B"], g["R1"], g["R2"],
                     g["omega"], g["E0"], g["D"], g["P_CJ"], v_cj, mode, width, p_min])


def released_chemical_energy(params: np.ndarray, hist: np.ndarray, m: np.ndarray) -> float:
    """Energy released so far [J]: burned mass times ``E0 / rho0``,
    ``sum(m F) E0 / rho0`` (``hist`` (n, 2) the items' history rows, ``m`` (n,))."""
    return float(np.dot(m, hist[:, H_BURN])) * params[P_E0] / params[P_DENSITY]


def lit(params: np.ndarray) -> bool:
    """Whether the burn needs lighting times (programmed or both)."""
    return int(params[P_MODE]) != 1


def detonation_velocity(params: np.ndarray) -> float:
    """``D`` [m/s] of a packed explosive."""
    return float(params[P_D])


HIGH_EXPLOSIVE = register(MaterialModel(
    name="high_explosive",
    history_names=("burn_fraction", "burn_clock"),
    pack=pack_explosive,
    update=explosive_update,
    schema=ExplosiveParams,
    history_init=lambda params: np.array([0.0, UNLIT]),
    fluid=True,
    explosive=True,
    test_density=None,
    released_energy=released_chemical_energy,
))

__all__ = ["HIGH_EXPLOSIVE", "ExplosiveParams", "PRESETS", "TNT", "UNLIT", "burn_fraction",
           "detonation_velocity", "explosive_update", "lit",
           "released_chemical_energy"]
