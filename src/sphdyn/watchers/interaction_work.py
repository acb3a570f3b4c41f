r"""The work of each interaction, booked apart (``[output] interaction_work``).

The stepper books the work of all interaction accelerations together at the
kick (:func:`sphdyn.integrate.kick`): :math:`E_{contact} = -W_{contact}`,

.. math:: W_{contact} \mathrel{+}= \Delta t^n \sum_i m_i\,\mathbf a^{ext}_i
          \cdot \mathbf v_i^n,

with :math:`\mathbf v^n` the mean of the velocities before and after the kick
and :math:`\Delta t^n` the kick's length. This module splits that sum by its
source, as LS-DYNA's ``sleout`` file splits the contact energy by interface:
the acceleration :math:`\mathbf a^I` each interaction :math:`I` added to every
part's ``a_ext`` is kept (the difference of ``a_ext`` across its ``forces``
call), and the events' changes of ``a_ext`` after the forces (an erosion
takes the contact forces of the eroded faces out, puts those of the new
surface in, and gives its particles the loads of the nodes they come from)
are kept as one more source, ``events``. Each source's work is the same sum
with its own accelerations:

.. math:: W_I \mathrel{+}= \Delta t^n \sum_i m_i\,\mathbf a^I_i
          \cdot \mathbf v_i^n,

so :math:`\sum_I W_I + W_{events} = W_{contact}` to round-off. The slaves of
tied, hybrid and sublayer couplings are booked nowhere (as in the kick): a
force on a slave is booked to the coupling that passes it to its master.
Interactions whose work is external work (gravity, blast, nodal loads:
``external = True``) book their own ``W_<name>`` and are left out here.

Cost: one (N, 3) array per source and part, and two copies of every part's
``a_ext`` per source and step: a diagnosis switch, off by default.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..state import BC_SLAVE


@njit(cache=True, error_model="numpy")
def kick_work(a, m, bc, v_mid, dt_kick):
    r"""Work of the accelerations ``a`` (n, 3) [m/s^2] over a kick [J]:
    :math:`\Delta t^n \sum_i m_i\,\mathbf a_i\cdot\mathbf v^n_i` over the first
    n items that are not slaves; ``m`` (N,) [kg], ``bc`` (N,), ``v_mid`` (N, 3)
    the kick's mean velocities [m/s]. Summed in order (the same bits on any
    number of threads)."""
    w = 0.0
    for i in range(a.shape[0]):
        if bc[i] != BC_SLAVE:
            w += m[i] * (a[i, 0] * v_mid[i, 0] + a[i, 1] * v_mid[i, 1]
                         + a[i, 2] * v_mid[i, 2])
    return w * dt_kick


class InteractionWork:
    """Work books per interaction of ``interactions`` (those not ``external``)
    and, with ``events``, one for the events' changes (module docstring).

    ``dofs(part)`` gives a part's kinematics tables (the stepper's
    :func:`sphdyn.stepper.dofs`; they live as long as the part, growing in
    place). The stepper calls :meth:`before` and
    :meth:`after` around each source's change of ``a_ext``, :meth:`clear_events`
    before the interactions' forces and :meth:`book` after each kick.
    """

    EVENTS = "events"

    def __init__(self, parts, interactions, events, dofs):
        self._tables = [(f"{part.name}.{j}", q) for part in parts
                        for j, q in enumerate(dofs(part))]
        # (names unique: the stepper checks)
        self.sources = [i.name for i in interactions if not getattr(i, "external", False)]
        if events:
            self.sources.append(self.EVENTS)
        self.work = {s: 0.0 for s in self.sources}  # [J]
        self._acc: dict[tuple[str, str], np.ndarray] = {}  # valid rows only (a view)
        self._store: dict[tuple[str, str], np.ndarray] = {}  # capacity
        self._snap: dict[str, np.ndarray] = {}
        self._snap_n: dict[str, int] = {}  # the parts' sizes at the snapshot

    def tracks(self, source: str) -> bool:
        return source in self.work

    @staticmethod
    def _room(store: dict, key, n: int) -> np.ndarray:
        """A (n, 3) view of ``store[key]``, grown (by 10 %) when too small."""
        buf = store.get(key)
        if buf is None or buf.shape[0] < n:
            buf = store[key] = np.zeros((int(n * 1.1) + 1, 3))
        return buf[:n]

    def before(self) -> None:
        """Keep every part's ``a_ext`` as it is before a source changes it."""
        for key, q in self._tables:
            snap = self._room(self._snap, key, q.n)
            snap[:] = q.a_ext
            self._snap_n[key] = q.n

    def after(self, source: str) -> None:
        """The source's accelerations: ``a_ext`` now minus before (rows added
        since, by an event, wholly the source's)."""
        for key, q in self._tables:
            n0 = self._snap_n[key]
            acc = self._room(self._store, (source, key), q.n)
            np.subtract(q.a_ext[:n0], self._snap[key][:n0], out=acc[:n0])
            acc[n0:] = q.a_ext[n0:]
            self._acc[source, key] = acc

    def clear_events(self) -> None:
        """No event change yet this step."""
        if self.EVENTS in self.work:
            for key, _ in self._tables:
                self._acc.pop((self.EVENTS, key), None)

    def book(self, dt_kick: float) -> None:
        """Add each source's work over the kick just taken (``v_mid`` set)."""
        for source in self.sources:
            w = 0.0
            for key, q in self._tables:
                acc = self._acc.get((source, key))
                if acc is not None:
                    w += kick_work(acc, q.m, q.bc, q.v_mid, dt_kick)
            self.work[source] += w

    def columns(self) -> dict[str, float]:
        """``W_contact_<source>`` [J] (J/m in 2D); their sum is ``-E_contact``."""
        return {f"W_contact_{s}": w for s, w in self.work.items()}

    # --------------------------------------------------------- checkpoint
    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        scalars = {f"work_{k}": s for k, s in enumerate(self.sources)}
        scalars.update({f"value_{k}": self.work[s] for k, s in enumerate(self.sources)})
        index = {s: k for k, s in enumerate(self.sources)}
        arrays = {f"{index[s]}_{key}": acc for (s, key), acc in self._acc.items()}
        return scalars, arrays

    def restore(self, scalars: dict, arrays: dict) -> None:
        saved = [scalars[f"work_{k}"] for k in range(len(self.sources))
                 if f"work_{k}" in scalars]
        if saved != self.sources:
            raise ValueError(f"the checkpoint's interaction work books {saved} are not "
                             f"this model's {self.sources}: it was written by another deck "
                             "or without [output] interaction_work")
        for k, s in enumerate(self.sources):
            self.work[s] = float(scalars[f"value_{k}"])
        self._acc.clear()
        for name, acc in arrays.items():
            k, key = name.split("_", 1)
            s = self.sources[int(k)]
            view = self._room(self._store, (s, key), acc.shape[0])
            view[:] = acc
            self._acc[s, key] = view
