r"""Gravity: a uniform body load on every item with mass of one part.

``[run] gravity`` :math:`\mathbf g` [m/s^2] adds :math:`\mathbf g` to the
acceleration of every particle or node with mass, the force
:math:`m_i\mathbf g` of each lumped mass (LS-DYNA's LOAD_BODY). Items without
mass (zero-mass crack particles) and the slaves of a tied or hybrid coupling
(their masters carry their mass, so their weight) get none. Rotational degrees
of freedom take none.

Its work over a kick, :math:`\sum_i m_i\,\mathbf g\cdot\mathbf v_i^n\,\Delta t^n`
(:math:`\mathbf v^n` the mid-kick velocity the stepper books every work at), is
external work: the stepper moves it from the interactions' work to
``W_external`` (:meth:`external_work`), and the history also reports it alone
as ``W_gravity_<part>`` (the loss of potential energy, :math:`M\,\mathbf g\cdot
\Delta\mathbf x_c` for a body whose centre of mass moved by
:math:`\Delta\mathbf x_c`).

The model and its tests: docs/theory.md, "Gravity".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..state import BC_SLAVE
from .base import InteractionBase


@njit(cache=True, error_model="numpy", parallel=True)
def add_gravity(m, bc, g, a_out):
    """``a_out[i] += g`` for every item with ``m[i] > 0`` that is not a slave.

    ``m`` (N,) [kg], ``bc`` (N,) boundary codes, ``g`` (3,) [m/s^2],
    ``a_out`` (N, 3) [m/s^2], added to in place.
    """
    for i in prange(m.shape[0]):
        if m[i] > 0.0 and bc[i] != BC_SLAVE:
            a_out[i, 0] += g[0]
            a_out[i, 1] += g[1]
            a_out[i, 2] += g[2]


@njit(cache=True, error_model="numpy")
def gravity_work(m, bc, g, v_mid, dt_kick):
    r"""Work of gravity over a kick [J]: :math:`\sum_i m_i\,\mathbf g\cdot
    \mathbf v_i^n\,\Delta t^n` over the items :func:`add_gravity` loads
    (``v_mid`` (N, 3) the mid-kick velocities [m/s]). Summed in order, so the
    same bits on any number of threads."""
    w = 0.0
    for i in range(m.shape[0]):
        if m[i] > 0.0 and bc[i] != BC_SLAVE:
            w += m[i] * (g[0] * v_mid[i, 0] + g[1] * v_mid[i, 1] + g[2] * v_mid[i, 2])
    return w * dt_kick


class Gravity(InteractionBase):
    """Gravity ``g`` (3,) [m/s^2] on the items of ``part`` (module docstring).

    The part's arrays are read at every call, so items added during the run
    (debris of eroded elements) are loaded too. Column ``W_gravity_<part>``:
    the work done so far [J] (J/m in 2D).
    """

    external = True  # its work is external work (W_external)

    def __init__(self, part, g):
        self.part = part
        self.name = f"gravity_{part.name}"
        self.g = np.asarray(g, dtype=float)
        self.work = 0.0  # total [J]
        self._kick = 0.0  # over the last kick [J]

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        q = self.part.kin
        add_gravity(q.m, q.bc, self.g, a_out)

    def after_kick(self, dt_kick: float) -> None:
        q = self.part.kin
        self._kick = gravity_work(q.m, q.bc, self.g, q.v_mid, dt_kick)
        self.work += self._kick

    def external_work(self) -> float:
        return self._kick

    def columns(self, t: float) -> dict[str, float]:
        return {f"W_{self.name}": self.work}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"work": self.work, "kick": self._kick}, {}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self.work = float(scalars["work"])
        self._kick = float(scalars["kick"])
