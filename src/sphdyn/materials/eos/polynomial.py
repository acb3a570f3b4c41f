r"""Linear polynomial equation of state (LS-DYNA's *EOS_LINEAR_POLYNOMIAL).

.. math::
    p = C_0 + C_1\mu + C_2\mu^2 + C_3\mu^3 + (C_4 + C_5\mu + C_6\mu^2)\,E,
    \qquad \mu = \rho/\rho_0 - 1,\quad E = \rho_0 e,

with ``E`` the internal energy per unit initial volume [Pa]; in expansion
(:math:`\mu < 0`) the :math:`C_2` and :math:`C_6` terms are dropped, as
LS-DYNA does. The ideal gas is :math:`C_4 = C_5 = \gamma - 1`, the others
zero: :math:`p = (\gamma - 1)\rho e`. Linear in ``e``:
:math:`p = a(\mu) + b(\mu)\,e` with :math:`b = \rho_0(C_4 + C_5\mu +
C_6\mu^2)`.

Isentropic sound speed,
:math:`c^2 = (\partial p/\partial\rho)_e + (p/\rho^2)(\partial p/\partial
e)_\rho`:

.. math::
    c^2 = \frac{C_1 + 2C_2\mu + 3C_3\mu^2 + (C_5 + 2C_6\mu)E}{\rho_0}
        + \frac{p\,b}{\rho^2}

(for the ideal gas :math:`c^2 = \gamma p/\rho`).

The model and its tests: docs/theory.md, "Fluids: gas and high explosive".
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy")
def polynomial_parts(mu, C0, C1, C2, C3, C4, C5, C6):
    """``(a, b_over_rho0, da, db)`` of :math:`p = a(\\mu) + b(\\mu) E`: the
    energy-free pressure ``a`` [Pa], the energy coefficient ``C4 + C5 mu +
    C6 mu^2`` [-] and their derivatives in ``mu`` (``C2``, ``C6`` terms only
    in compression, module docstring)."""
    if mu < 0.0:
        C2 = 0.0
        C6 = 0.0
    a = C0 + mu * (C1 + mu * (C2 + mu * C3))
    da = C1 + mu * (2.0 * C2 + 3.0 * C3 * mu)
    b = C4 + mu * (C5 + mu * C6)
    db = C5 + 2.0 * C6 * mu
    return a, b, da, db


@njit(cache=True, error_model="numpy")
def polynomial_pressure(mu, E, C0, C1, C2, C3, C4, C5, C6):
    """Pressure [Pa] at ``mu = rho/rho0 - 1`` and energy per initial volume
    ``E`` [Pa] (module docstring)."""
    a, b, _, _ = polynomial_parts(mu, C0, C1, C2, C3, C4, C5, C6)
    return a + b * E


@njit(cache=True, error_model="numpy")
def polynomial_sound_speed(rho, rho0, E, C0, C1, C2, C3, C4, C5, C6):
    """Isentropic sound speed [m/s] (module docstring); the square floored at
    zero."""
    mu = rho / rho0 - 1.0
    a, b, da, db = polynomial_parts(mu, C0, C1, C2, C3, C4, C5, C6)
    p = a + b * E
    c2 = (da + db * E) / rho0 + p * b * rho0 / (rho * rho)
    return math.sqrt(c2) if c2 > 0.0 else 0.0
