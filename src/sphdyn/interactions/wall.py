"""A rigid planar wall acting on the particles of an SPH part (an Interaction).

The penalty force, its stiffness options (paper eq. 8 and 9) and friction
are in :mod:`.wall_contact`; this module keeps the wall's motion (a velocity
reached over a linear ramp), its force totals and impulse, and its history
columns ``F_wall_<name>`` (normal force), ``F_wall_<name>_t`` (tangential),
``I_wall_<name>`` (impulse given so far), ``contacts_<name>`` and, for a
moving wall, ``d_wall_<name>`` (travel along the normal).

The model and its tests: docs/theory.md, "Rigid wall with penalty contact".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..analysis.fragments import window_mean_force
from .base import InteractionBase
from .wall_contact import (BORN, STIFFNESS_BULK, STIFFNESS_MASS, bulk_contact_time_step,
                           column_sums, wall_contact)

STIFFNESS = {"mass": STIFFNESS_MASS, "bulk": STIFFNESS_BULK}


@dataclass
class WallSpec:
    """A rigid planar wall: plane, contact law and motion (SI units)."""

    name: str
    point: np.ndarray
    normal: np.ndarray  # unit normal towards the bodies
    method: int  # STIFFNESS_MASS or STIFFNESS_BULK
    alpha: float
    friction: float
    thickness_factor: float
    bulk_modulus: float | None = None  # [Pa]; None: each particle's material
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))  # [m/s]
    ramp_time: float = 0.0  # [s] linear velocity ramp from rest

    def travel(self, t: float) -> float:
        """Distance travelled in units of the final velocity [s]:
        ``t^2 / (2 T)`` during the ramp ``t < T``, ``t - T/2`` after it."""
        T = self.ramp_time
        return t * t / (2.0 * T) if t < T else t - 0.5 * T

    def point_at(self, t: float) -> np.ndarray:
        """A point of the wall plane at time ``t`` [s]: point + velocity travel(t)."""
        return self.point + self.velocity * self.travel(t)

    def velocity_at(self, t: float) -> np.ndarray:
        """Wall velocity at time ``t`` [s]: velocity min(t / T, 1)."""
        T = self.ramp_time
        return self.velocity * (min(t / T, 1.0) if T > 0.0 else 1.0)


class Wall(InteractionBase):
    """Penalty contact of one rigid wall with the particles of ``part``.

    ``part`` is an SPH part (its particles provide ``x, v, m, vol0, rho0``
    and ``bulk_modulus``). The force on each particle goes to a shared work
    array ``wall_force`` of the particle store; its sum is the wall's total.
    """

    def __init__(self, spec: WallSpec, part):
        self.spec = spec
        self.name = spec.name
        self.part = part
        p = part.p
        p.add("wall_force", (3,))
        self._kbulk_name = "bulk_modulus"
        if spec.bulk_modulus is not None:
            self._kbulk_name = f"kbulk_{spec.name}"
            p.add(self._kbulk_name, (), fill=spec.bulk_modulus)
        self.total = np.zeros(3)  # force on the bodies [N] (N/m in 2D)
        self.count = 0
        # impulse the wall has given the bodies so far [N s] (N s/m in 2D):
        # the sum of F^n dt_kick over the kicks, so it equals the bodies'
        # momentum change through the wall to round-off
        self.impulse = np.zeros(3)
        # each particle's spring: its allowance [m] and stiffness per unit
        # mass [1/s^2] of the last evaluation (wall_contact's energy rule);
        # kept here, not among the particles' state, so that a template's
        # row copied into injected particles does not carry them. Rows added
        # later hold the stiffness's fill, BORN: the kernel takes their
        # penetration at their first evaluation as allowance
        self._pen0 = f"wall_allowance_{spec.name}"
        self._k_last = f"wall_stiffness_{spec.name}"
        p.add(self._pen0, ())
        p.add(self._k_last, (), fill=BORN)[:] = 0.0  # present at the start: none
        self._dt = self._limit()
        p.on_grow(self._grown)

    def _grown(self, n_old: int, n_new: int) -> None:
        """Particles were added: the bulk spring's step limit again."""
        self._dt = self._limit()

    def _limit(self) -> float:
        p, w = self.part.p, self.spec
        if w.method != STIFFNESS_BULK or p.n == 0:
            return np.inf
        return 0.5 * bulk_contact_time_step(p.m, p.vol0, p.rho0,
                                            getattr(p, self._kbulk_name), p.dim, w.alpha)

    def stable_dt(self) -> float:
        """Half the bulk spring's limit :math:`2\\sqrt{m/k}` (mass springs: inf)."""
        return self._dt

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p, w = self.part.p, self.spec
        self.count = int(wall_contact(
            p.x, p.v, p.m, p.vol0, p.rho0, getattr(p, self._kbulk_name), p.dim,
            w.point_at(t), w.normal, w.velocity_at(t), w.thickness_factor, w.method,
            w.alpha, w.friction, dt, a_out, p.wall_force, getattr(p, self._pen0),
            getattr(p, self._k_last)))
        column_sums(p.wall_force, self.total)

    def after_kick(self, dt_kick: float) -> None:
        self.impulse += self.total * dt_kick

    def columns(self, t: float) -> dict[str, float]:
        w, f = self.spec, self.total
        fn = float(f @ w.normal)
        out = {f"F_wall_{w.name}": fn,
               f"I_wall_{w.name}": float(self.impulse @ w.normal),
               # math.hypot, not numpy's norm: the same bits with any numpy
               f"F_wall_{w.name}_t": math.hypot(*(f - fn * w.normal)),
               f"contacts_{w.name}": float(self.count)}
        if w.velocity.any():
            out[f"d_wall_{w.name}"] = float(w.velocity @ w.normal) * w.travel(t)
        return out

    def summary(self, history: dict, window: float) -> dict:
        """``peak_F_wall_<name>``: the largest normal force [N] (N/m in 2D) of the
        history, and ``peak_F_wall_<name>_mean``: the largest mean over
        ``window`` seconds (:func:`sphdyn.analysis.fragments.window_mean_force`,
        from the impulse column, exact however sparse the records)."""
        col = f"F_wall_{self.spec.name}"
        if not history.get(col, np.zeros(0)).size:
            return {}
        mean = window_mean_force(history["time"], history[f"I_wall_{self.spec.name}"],
                                 window)
        return {f"peak_{col}": float(np.max(history[col])),
                f"peak_{col}_mean": float(np.max(mean))}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        p = self.part.p
        return {}, {"impulse": self.impulse, "allowance": getattr(p, self._pen0),
                    "stiffness": getattr(p, self._k_last)}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self.impulse[...] = arrays["impulse"]
        p = self.part.p
        setattr(p, self._pen0, arrays["allowance"])
        setattr(p, self._k_last, arrays["stiffness"])
