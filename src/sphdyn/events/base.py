"""The Event protocol: a change of the model between two steps.

After each step the :class:`~sphdyn.stepper.Stepper` asks every event
``due(stepper)`` and, if so, calls ``apply(stepper)``. An event may add
items to a part (``part.kin.grow(k)``: every per-item array, the neighbour
lists and the material groups follow, see :mod:`sphdyn.state.store`).
Erosion of elements into particles (the erosion issue) is an event;
:mod:`.inject` proves the mechanism. ``state()`` / ``restore()`` keep what
an event must remember across a restart (whether it fired).

Optional: ``columns(t)``, the event's history columns, and
``energy_removed`` [J], energy the event took out of the model, which the
stepper's ``E_total`` books (:mod:`.erosion`, :mod:`.domain_exit`; any
part or interaction may keep this book too). An event that changes a mesh
calls ``withdraw_forces()`` (if they have it) before the change and
``mesh_changed()`` after it on the interactions whose ``solid`` is that part.
"""

from __future__ import annotations

from typing import Protocol


class Event(Protocol):
    name: str

    def due(self, stepper) -> bool: ...
    def apply(self, stepper) -> None: ...
    def state(self) -> dict: ...
    def restore(self, scalars: dict) -> None: ...
