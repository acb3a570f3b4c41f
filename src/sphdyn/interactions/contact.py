"""Penalty contact between particles of different bodies of an SPH part.

The pair force and its stiffness are in :mod:`.particle_contact`; this
Interaction keeps the contact neighbour list (current configuration, the
same absolute Verlet skin as the SPH list or larger) and reports
``contacts_bodies``, the number of particles touching another body.

The model and its tests: docs/theory.md, "Contact between bodies".
"""

from __future__ import annotations

import numpy as np

from ..neighbours import build_neighbours, update_neighbours
from .base import InteractionBase
from .particle_contact import contact_time_step, particle_contact


class ParticleContact(InteractionBase):
    """Contact between the bodies of ``part`` (an SPH part).

    ``alpha`` scales the bulk-modulus stiffness; particles touch when closer
    than ``distance_factor`` times their mean size.
    """

    name = "contact"

    def __init__(self, part, alpha: float, distance_factor: float):
        self.part = part
        self.alpha, self.distance_factor = alpha, distance_factor
        self.count = 0
        n = part.p.n
        self.allow = np.zeros(n)  # overlap allowances [m] (particle_contact)
        self.over = np.zeros(n)  # scratch: each particle's deepest raw overlap
        self._build()
        part.p.on_grow(self._grown)

    def _grown(self, n_old: int, n_new: int) -> None:
        """New particles keep the overlap they are born with (no force from it)."""
        self._build()
        p = self.part.p
        self.over = np.zeros(n_new)
        scratch = np.zeros((n_new, 3))
        particle_contact(p.x, p.m, p.size, p.bulk_modulus, p.body, p.tl, p.dim,
                         self.nl.offsets, self.nl.idx, self.alpha, self.distance_factor,
                         np.full(n_new, np.inf), self.over, scratch)
        self.allow = np.concatenate([self.allow[:n_old], self.over[n_old:n_new]])

    def _build(self) -> None:
        p, part = self.part.p, self.part
        self._dt = 0.5 * contact_time_step(p.m, p.size, p.bulk_modulus, p.dim, self.alpha) \
            if p.n else np.inf
        # the same absolute skin as the SPH list (or larger): a skin scaled
        # with the short contact radius alone forced a rebuild every few
        # steps in the rings benchmark (0.125 mm at 15 m/s closing speed)
        r0 = part.kernel.radius_factor * float(p.h0.max()) if p.n else 0.0
        skin = part.s.skin_factor * max(r0, self.distance_factor * float(p.size.max()))
        self.nl = build_neighbours(p.x, p.size, self.distance_factor, skin, p.dim)

    def stable_dt(self) -> float:
        """Half the contact springs' limit :math:`2\\sqrt{m/(n k)}`."""
        return self._dt

    def update_geometry(self, t: float) -> None:
        p = self.part.p
        self.nl = update_neighbours(self.nl, p.x, p.size, p.dim)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p = self.part.p
        self.count = int(particle_contact(
            p.x, p.m, p.size, p.bulk_modulus, p.body, p.tl, p.dim, self.nl.offsets,
            self.nl.idx, self.alpha, self.distance_factor, self.allow, self.over, a_out))
        np.minimum(self.allow, self.over, out=self.allow)  # allowances only shrink

    def columns(self, t: float) -> dict[str, float]:
        return {"contacts_bodies": float(self.count)}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        nl = self.nl
        return {}, {"nl_offsets": nl.offsets, "nl_idx": nl.idx, "nl_x_ref": nl.x_ref,
                    "nl_h_ref": nl.h_ref, "allow": self.allow}

    def restore(self, scalars: dict, arrays: dict) -> None:
        nl = self.nl
        nl.offsets = arrays["nl_offsets"].copy()
        nl.idx = arrays["nl_idx"].copy()
        nl.x_ref = arrays["nl_x_ref"].copy()
        nl.h_ref = arrays["nl_h_ref"].copy()
        if "allow" in arrays:  # (checkpoints written before the allowances: none)
            self.allow = arrays["allow"].copy()
            self.over = np.zeros(self.allow.size)
