"""The Part protocol: something with items that move (an SPH body set, a mesh).

The :class:`~sphdyn.stepper.Stepper` knows no physics; it asks each part

* ``kin``: its :class:`~sphdyn.state.Kinematics` (x, v, a, a_ext, m, bc, ...),
  which the stepper kicks with the central-difference scheme;
* ``stable_dt()``: its stable time step and the controlling item;
* ``start(dt)``: accelerations of the initial state (no material update);
* ``drift(dt)``: the position update (a part may smooth the velocity, XSPH);
* ``update_geometry(t, dt)``: neighbours, reference configuration, velocity
  gradient, density and smoothing length at the new positions;
* ``internal_forces(t, dt)``: material update and the divergence of stress
  into ``kin.a`` (overwritten), heat from dissipation;
* ``energies()``: internal energy and its dissipated part [J];
* ``columns()``: its history columns; ``fields()``: output fields it computes;
* ``state()`` / ``restore(scalars, arrays)``: its checkpoint data.

Optional: ``frame()``, its own picture in a frame (a mesh's cells; a part
without it moves the frame's points, the particles), ``summary()``, what it
adds to the run's summary, ``describe_limit(k)`` and ``hotspot()``, its words
in a diagnosis, ``items_label``, what its items are called there ("node(s)
of mesh 'beam'"), and ``energy_released`` [J], energy its materials released
into the model (an explosive's), which the stepper's ``E_total`` books.

Parts register by kind in :data:`PART_KINDS` (the FEM issue adds mesh parts).
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np

from ..state import Kinematics


class Part(Protocol):
    name: str
    kind: str  # set by register_part
    kin: Kinematics

    def stable_dt(self) -> tuple[float, int]: ...
    def start(self, dt: float) -> None: ...
    def drift(self, dt: float) -> None: ...
    def update_geometry(self, t: float, dt: float) -> None: ...
    def internal_forces(self, t: float, dt: float) -> None: ...
    def energies(self) -> tuple[float, float]: ...
    def columns(self) -> dict[str, float]: ...
    def fields(self) -> dict[str, Callable[[], np.ndarray]]: ...
    def state(self) -> tuple[dict, dict[str, np.ndarray]]: ...
    def restore(self, scalars: dict, arrays: dict[str, np.ndarray]) -> None: ...


#: kind name -> part class
PART_KINDS: dict[str, type] = {}


def register_part(kind: str):
    """Class decorator: make a part class known under ``kind``."""
    def deco(cls):
        if kind in PART_KINDS and PART_KINDS[kind] is not cls:
            raise ValueError(f"part kind {kind!r} is registered already")
        PART_KINDS[kind] = cls
        cls.kind = kind
        return cls
    return deco
