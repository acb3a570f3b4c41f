"""The Interaction protocol: forces between parts, or between a part and the world.

Walls, particle-particle contact and (with the FEM issue) the SPH-FEM
couplings, prescribed motion, loads and damping. The
:class:`~sphdyn.stepper.Stepper` asks each interaction

* ``stable_dt()``: its stability limit (``inf`` if it needs none);
* ``prescribe(t, dt)``: before the kick of the step [t, t + dt], the
  velocities of prescribed degrees of freedom (``kin.bc_v``);
* ``update_geometry(t)``: after the drift (contact neighbour lists);
* ``forces(t, dt, a_out)``: accelerations **added** to ``a_out``, the
  ``a_ext`` of the part it acts on (``dt`` is the stable step, which
  mass-based penalty springs use); it also refreshes what it reports;
* ``after_kick(dt_kick)``: bookkeeping over the kick (impulses);
* ``external_work()``: the part of its forces' work over the last kick that
  is external work (gravity; such an interaction says ``external = True``),
  which the stepper books in ``W_external`` instead of with the
  interactions' (``E_contact``);
* ``constrain(t, dt)``: after the kick of the step [t, t + dt], the
  tied and hybrid couplings set their slaves' positions and velocities
  from their masters';
* ``columns(t)``: its history columns; ``state()`` / ``restore()``;
* ``summary(history, window)``: what it adds to the run's summary from the
  whole history (``{column: (K,) array}``; ``window`` the deck's
  ``[output] force_window`` [s]): a wall's peak forces, a boundary's peak
  reaction.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class Interaction(Protocol):
    name: str

    def stable_dt(self) -> float: ...
    def prescribe(self, t: float, dt: float) -> None: ...
    def update_geometry(self, t: float) -> None: ...
    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None: ...
    def after_kick(self, dt_kick: float) -> None: ...
    def external_work(self) -> float: ...
    def constrain(self, t: float, dt: float) -> None: ...
    def columns(self, t: float) -> dict[str, float]: ...
    def summary(self, history: dict, window: float) -> dict: ...
    def state(self) -> tuple[dict, dict[str, np.ndarray]]: ...
    def restore(self, scalars: dict, arrays: dict[str, np.ndarray]) -> None: ...


class InteractionBase:
    """Defaults for the optional hooks: nothing to do, nothing to keep."""

    #: True for loads whose work is external work (``external_work``); the
    #: others' work is the interactions' (``E_contact``, and with ``[output]
    #: interaction_work`` their own ``W_contact_<name>``)
    external = False

    def stable_dt(self) -> float:
        return np.inf

    def prescribe(self, t: float, dt: float) -> None:
        return None

    def update_geometry(self, t: float) -> None:
        return None

    def after_kick(self, dt_kick: float) -> None:
        return None

    def external_work(self) -> float:
        return 0.0

    def constrain(self, t: float, dt: float) -> None:
        return None

    def summary(self, history: dict, window: float) -> dict:
        return {}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {}, {}

    def restore(self, scalars: dict, arrays: dict[str, np.ndarray]) -> None:
        return None
