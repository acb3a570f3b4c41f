r"""Jones-Wilkins-Lee equation of state of detonation products.

.. math::
    p = A\Big(1 - \frac{\omega}{R_1 V}\Big)e^{-R_1 V}
      + B\Big(1 - \frac{\omega}{R_2 V}\Big)e^{-R_2 V} + \frac{\omega E}{V},
    \qquad V = \frac{\rho_0}{\rho},\quad E = \rho_0 e

with ``E`` the internal energy per unit *initial* volume [Pa] (``e`` per unit
mass [J/kg]); Lee, Hornig & Kury (1968), UCRL-50422; LS-DYNA's
*EOS_JWL. Since :math:`\omega E / V = \omega \rho e`, the pressure is
:math:`p = p_c(V) + \omega\rho e`, linear in ``e``.

The isentropic sound speed,
:math:`c^2 = (\partial p/\partial\rho)_e + (p/\rho^2)(\partial p/\partial
e)_\rho`, with :math:`(\partial p/\partial\rho)_e = -(V/\rho)(\partial
p/\partial V)_E` and :math:`(\partial p/\partial e)_\rho = \omega\rho`:

.. math:: c^2 = \frac{-V\,(\partial p/\partial V)_E + \omega p}{\rho}.

Chapman-Jouguet state (:func:`cj_state`): the point of the products'
Hugoniot from the unreacted state (``V = 1``, ``p = 0``, energy ``E0``),

.. math:: E = E_0 + \tfrac12 p (1 - V) \;\Rightarrow\;
          p_H(V) = \frac{p_c(V) + \omega E_0 / V}{1 - \omega (1 - V)/(2V)},

where the Rayleigh line :math:`p = \rho_0 D^2 (1 - V)` touches it: the
smallest detonation speed :math:`D^2 = p_H / (\rho_0 (1 - V))` (Fickett &
Davis, *Detonation*, 1979, ch. 2).

The model and its tests: docs/theory.md, "Fluids: gas and high explosive".
"""

from __future__ import annotations

import math

from numba import njit
from scipy.optimize import minimize_scalar


@njit(cache=True, error_model="numpy")
def jwl_parts(V, A, B, R1, R2, w):
    r"""The cold part :math:`p_c(V)` of the JWL pressure and its derivative.

    Parameters
    ----------
    V : float, relative volume :math:`\rho_0/\rho` (> 0).
    A, B : float, JWL constants [Pa].
    R1, R2, w : float, JWL constants [-].

    Returns
    -------
    pc : float, :math:`A(1-\omega/(R_1V))e^{-R_1V} + B(1-\omega/(R_2V))e^{-R_2V}` [Pa].
    dpc : float, :math:`dp_c/dV` [Pa].
    """
    e1 = math.exp(-R1 * V)
    e2 = math.exp(-R2 * V)
    iv = 1.0 / V
    pc = A * (1.0 - w * iv / R1) * e1 + B * (1.0 - w * iv / R2) * e2
    dpc = (A * e1 * (w * iv * iv / R1 - R1 + w * iv)
           + B * e2 * (w * iv * iv / R2 - R2 + w * iv))
    return pc, dpc


@njit(cache=True, error_model="numpy")
def jwl_pressure(V, E, A, B, R1, R2, w):
    """JWL pressure [Pa] at relative volume ``V`` and energy per initial volume
    ``E`` [Pa] (module docstring)."""
    pc, _ = jwl_parts(V, A, B, R1, R2, w)
    return pc + w * E / V


@njit(cache=True, error_model="numpy")
def jwl_sound_speed(rho, V, E, A, B, R1, R2, w):
    r"""Isentropic sound speed of the products [m/s]:
    :math:`c^2 = (-V\,\partial p/\partial V|_E + \omega p)/\rho`, with
    :math:`\partial p/\partial V|_E = p_c'(V) - \omega E/V^2`; ``rho`` the
    density [kg/m^3], ``V`` the relative volume, ``E`` the energy per initial
    volume [Pa]. The square is floored at zero (a state in tension)."""
    pc, dpc = jwl_parts(V, A, B, R1, R2, w)
    p = pc + w * E / V
    c2 = (-V * (dpc - w * E / (V * V)) + w * p) / rho
    return math.sqrt(c2) if c2 > 0.0 else 0.0


def jwl_hugoniot_pressure(V: float, A: float, B: float, R1: float, R2: float,
                          w: float, E0: float) -> float:
    """Pressure [Pa] on the products' Hugoniot from the unreacted state
    (``V = 1``, ``p = 0``, energy per initial volume ``E0`` [Pa]) at relative
    volume ``V`` (module docstring)."""
    pc, _ = jwl_parts(V, A, B, R1, R2, w)
    return (pc + w * E0 / V) / (1.0 - w * (1.0 - V) / (2.0 * V))


def cj_state(A: float, B: float, R1: float, R2: float, w: float, E0: float,
             rho0: float) -> tuple[float, float, float]:
    """Chapman-Jouguet state of a JWL explosive: ``(V_CJ, p_CJ [Pa], D_CJ [m/s])``,
    the tangency of the Rayleigh line with the Hugoniot (module docstring),
    found by minimising :math:`D^2(V)` on the Hugoniot for ``0.3 <= V < 1``
    (to 1e-12 in ``V``)."""
    def d2(V):
        return jwl_hugoniot_pressure(V, A, B, R1, R2, w, E0) / (rho0 * (1.0 - V))

    res = minimize_scalar(d2, bounds=(0.3, 1.0 - 1e-9), method="bounded",
                          options={"xatol": 1e-12})
    V = float(res.x)
    return V, jwl_hugoniot_pressure(V, A, B, R1, R2, w, E0), math.sqrt(d2(V))
