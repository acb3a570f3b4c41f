"""Inject particles into an SPH part at a given time (the event mechanism's test).

New particles copy every state array of a template particle (material,
density, smoothing length, stress, history, ...) and get their own
positions and velocity; their reference position ``x0`` is where they are
born. They join the template's material group, and the neighbour lists are
rebuilt (:meth:`sphdyn.parts.sph.part.SPHPart._grown`). Their
acceleration is zero until the next step computes it.
"""

from __future__ import annotations

import numpy as np

from ..state import STATE


class InjectParticles:
    """Add particles at ``positions`` (k, 3) [m] with ``velocity`` (3,) [m/s]
    at the first step end with ``t >= time`` [s], copied from particle
    ``template`` of the part named ``part``."""

    def __init__(self, name: str, time: float, positions, velocity, template: int,
                 part: str = "sph"):
        self.name = name
        self.time = float(time)
        self.positions = np.atleast_2d(np.asarray(positions, float))
        self.velocity = np.asarray(velocity, float)
        self.template = int(template)
        self.part = part
        self.fired = False

    def due(self, stepper) -> bool:
        return not self.fired and stepper.t >= self.time

    def apply(self, stepper) -> None:
        p = stepper.part(self.part).p
        k, i = self.positions.shape[0], self.template
        if not 0 <= i < p.n:
            raise ValueError(f"event {self.name!r}: template particle {i} does not exist "
                             f"(the part has {p.n})")
        snapshot = {name: getattr(p, name)[i].copy() for name in p.names(STATE)}
        # every state array gets the template's row before the listeners run
        rows = p.grow(k, notify=False)
        for name, row in snapshot.items():
            getattr(p, name)[rows] = row
        p.x[rows] = self.positions
        p.x0[rows] = self.positions
        p.v[rows] = self.velocity
        p.a[rows] = 0.0
        p.a_ext[rows] = 0.0
        p.notify_grown(rows.start, rows.stop)
        self.fired = True

    def state(self) -> dict:
        return {"fired": int(self.fired)}

    def restore(self, scalars: dict) -> None:
        self.fired = bool(scalars.get("fired", 0))
