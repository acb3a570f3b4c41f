"""Particles leaving the domain box are removed from the calculation.

LS-DYNA's SPH box (*CONTROL_SPH, BOXID): a blast's detonation products fly
off at several km/s, and a box wide enough to hold them for the whole run
makes the neighbour grid coarse and the search slow. With ``[domain]
outside = "remove"`` the particles of the SPH part that leave the box are
taken out (:meth:`sphdyn.parts.sph.part.SPHPart.deactivate`): fixed where
they left, out of the neighbour lists. Their kinetic energy (after the
coming half kick, where the stepper books it) and internal energy leave the
model and are counted in ``E_total`` as removed (``energy_removed``; the
history's ``E_left_domain``, ``particles_removed``); their mass stays in the
particle arrays. Total-Lagrangian particles and mesh nodes that leave still
stop the run (the guard).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..watchers.guards import outside_box


@njit(cache=True, error_model="numpy", parallel=True)
def count_outside(x, active, tl, lo, hi):
    """How many active, updated-Lagrangian items of ``x`` (N, 3) lie outside
    ``[lo, hi]`` (``active`` (N,) int8, ``tl`` (N,) bool): the every-step
    check, parallel and allocating nothing."""
    n = 0
    for i in prange(x.shape[0]):
        if active[i] != 0 and not tl[i] and outside_box(x, i, lo, hi):
            n += 1
    return n


@njit(cache=True, error_model="numpy")
def outside_rows(x, active, tl, lo, hi, n):
    """Indices (n,) int64, ascending, of the ``n`` items
    :func:`count_outside` counted."""
    out = np.empty(n, np.int64)
    k = 0
    for i in range(x.shape[0]):
        if active[i] != 0 and not tl[i] and outside_box(x, i, lo, hi):
            out[k] = i
            k += 1
    return out


class DomainExit:
    """Remove the SPH particles that left ``[lo, hi]`` (module docstring)."""

    name = "domain_exit"

    def __init__(self, part, lo, hi):
        self.part = part
        self.lo = np.asarray(lo, float)
        self.hi = np.asarray(hi, float)
        self.removed = 0
        self.energy_removed = 0.0  # counted in the stepper's E_total

    def due(self, stepper) -> bool:
        return True

    def apply(self, stepper) -> None:
        p = self.part.p
        n = count_outside(p.x, p.active, p.tl, self.lo, self.hi)
        if n == 0:
            return
        rows = outside_rows(p.x, p.active, p.tl, self.lo, self.hi, n)
        v = p.v[rows] + 0.5 * stepper.dt_prev * p.a[rows]  # after the coming half kick
        m, mi = p.m[rows], p.inertia()[rows]  # (mi: with a mass scaling's)
        self.energy_removed += float(0.5 * np.sum(mi * np.sum(v * v, axis=1))
                                     + np.dot(m, p.e[rows]))
        self.removed += int(rows.size)
        self.part.deactivate(rows)

    def columns(self, t: float) -> dict[str, float]:
        return {"particles_removed": float(self.removed), "E_left_domain": self.energy_removed}

    def state(self) -> dict:
        return {"removed": self.removed, "energy_removed": self.energy_removed}

    def restore(self, scalars: dict) -> None:
        self.removed = int(scalars.get("removed", 0))
        self.energy_removed = float(scalars.get("energy_removed", 0.0))
