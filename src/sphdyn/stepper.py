r"""One explicit step over parts, interactions and events; the stepper knows no physics.

Central differences (leapfrog, :mod:`sphdyn.integrate`), state at
:math:`t^n`: :math:`\mathbf x^n,\ \mathbf v^{n-1/2},\ \mathbf a^n`:

1. time step: the smallest of the parts' and interactions' stable steps and
   ``dt_max`` (monitors' ``before_step`` see it: the collapse guard);
2. interactions' ``prescribe`` (prescribed velocities of the step), kick
   of every part to :math:`\mathbf v^{n+1/2}` with its boundary
   conditions, booking the kinetic energy at :math:`t^n`, the work of the
   interaction accelerations ``a_ext`` and of the boundary reactions;
   interactions' ``after_kick`` (impulses) and ``constrain`` (tied DOFs);
   monitors' ``after_kick`` see the state at :math:`t^n` (history records);
3. drift of every part to :math:`\mathbf x^{n+1}`;
4. parts' ``update_geometry``, interactions' ``update_geometry``;
5. parts' ``internal_forces`` (:math:`\sigma^{n+1}` and ``a``), then the
   interactions' forces into ``a_ext``, added to ``a``: :math:`\mathbf a^{n+1}`
   (with selective mass scaling, :mod:`sphdyn.mass_scaling`, turned into the
   accelerations of the items' inertia);
6. events (a change of the model between steps), then monitors'
   ``after_step`` (guards, history, frames, checkpoints).

The energy balance :math:`E_{total} = E_{kin} + E_{int} + E_{contact} -
W_{ext} + E_{removed} - E_{chemical}`, with :math:`E_{contact} = -W_{contact}`
the negative work of the interaction forces, is recorded by
:meth:`Stepper.record` with the items' ``columns``. Two optional books of any
part, interaction or event enter it: ``energy_removed`` [J], energy taken out
of the model and still counted (an erosion event's eroded elements, particles
that left the domain; column ``E_removed``), and ``energy_released`` [J],
energy the model was given from inside (an explosive's chemical energy;
column ``E_chemical``); an item without a book leaves it None.
"""

from __future__ import annotations

import numpy as np

from .integrate import KICK_BLOCK, kick, kick_scratch
from .watchers.interaction_work import InteractionWork
from .state import BC_SLAVE


def _add(total, value):
    """``total + value``, with the first value taken as it is (no ``0.0 +``)."""
    return value if total is None else total + value


def _own_state(scalars: dict, groups: dict, key: str) -> tuple[dict, dict]:
    """The scalars (prefix ``key.`` taken off) and the array group ``key`` of one
    part or interaction in a checkpoint (:meth:`Stepper.state`)."""
    pre = key + "."
    return ({k[len(pre):]: v for k, v in scalars.items() if k.startswith(pre)},
            groups.get(key, {}))


def _book(items, name: str) -> float | None:
    """The sum of the items' energy book ``name`` [J]; None if no item keeps
    one (the optional ``energy_removed`` and ``energy_released``)."""
    values = [v for v in (getattr(item, name, None) for item in items) if v is not None]
    return float(sum(values)) if values else None


def dofs(part) -> list:
    r"""The kinematics tables the stepper kicks for ``part``: its translations
    ``kin`` and, for parts with rotational degrees of freedom (beams), the
    rotations ``kin.rot`` (angular velocity in ``v``, rotary inertia in ``m``:
    the same kick, the kinetic energy :math:`\tfrac12 I\omega^2`)."""
    rot = getattr(part.kin, "rot", None)
    return [part.kin] if rot is None else [part.kin, rot]


class Stepper:
    """Advance parts, interactions and events in time.

    Parameters
    ----------
    parts : the parts (each with ``kin``; see :mod:`sphdyn.parts.base`).
    interactions : see :mod:`sphdyn.interactions.base`; each acts on one part
        (``interaction.part``) and adds into that part's ``a_ext``.
    events : see :mod:`sphdyn.events.base`.
    monitors : objects with any of ``before_step(stepper, dt, k, part)``,
        ``after_kick(stepper)``, ``after_step(stepper)``.
    dt_max : largest step [s].
    interaction_work : book each interaction's work apart
        (:mod:`sphdyn.watchers.interaction_work`; columns ``W_contact_<name>``).
    mass_scaling : a :class:`~sphdyn.mass_scaling.MassScaling` or None: inertia
        added to the items that limit the step, once the parts have started.
    """

    def __init__(self, parts, interactions=(), events=(), monitors=(), dt_max=np.inf,
                 interaction_work=False, mass_scaling=None):
        self.parts = list(parts)
        self.interactions = list(interactions)
        self.events = list(events)
        for kind, items in (("part", self.parts), ("interaction", self.interactions),
                            ("event", self.events)):
            names = [item.name for item in items]
            twice = sorted({n for n in names if names.count(n) > 1})
            if twice:  # their checkpoint groups and history columns would collide
                raise ValueError(f"two {kind}s are named {twice[0]!r}: give each its own name")
        self.monitors = list(monitors)
        self.dt_max = dt_max
        self.t = 0.0
        self.step_count = 0
        self.dt_prev = 0.0  # 0 before the first kick (half kick)
        self.dt_step = 0.0  # the last step taken (shortened to land on t_stop)
        self.kinetic = 0.0  # kinetic energy at the last kick's time [J]
        self.work_contact = 0.0  # work of the interaction forces [J]
        self.work_external = 0.0  # work of the boundary-condition reactions [J]
        self._kick_sums: dict[str, np.ndarray] = {}  # per part, grown with it
        # per part (the energy guard's diagnosis, sphdyn.watchers.monitors.EnergyGuard):
        # kinetic energy at the last kick [J], the work done on its items by
        # interaction accelerations and boundary reactions so far [J], and its
        # kinetic plus internal energy at the first kick [J]
        self.part_kinetic = {p.name: 0.0 for p in self.parts}
        self.part_work = {p.name: 0.0 for p in self.parts}
        self.part_start: dict[str, float] = {}
        self.books = (InteractionWork(self.parts, self.interactions, self.events, dofs)
                      if interaction_work else None)
        for part in self.parts:
            for q in dofs(part):
                q.add("v_mid", (3,))
        self.mass_scaling = mass_scaling
        self.dt0, _, _ = self.stable_dt()
        for part in self.parts:
            part.start(self.dt0)
        if mass_scaling is not None:  # the items' steps of the started state
            mass_scaling.apply(self.parts, self.interactions)
            dt_before = self.dt0
            self.dt0, _, _ = self.stable_dt()
            mass_scaling.steps = (dt_before, self.dt0)
        self.dt_stable = self.dt0  # the step before shortening to land on t_stop
        self._interaction_forces(self.dt0)

    # ------------------------------------------------------------- access
    def part(self, name: str):
        """The part called ``name``."""
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(f"no part {name!r}; parts: {[p.name for p in self.parts]}")

    def add_monitor(self, monitor) -> None:
        self.monitors.append(monitor)

    def _notify(self, hook: str, *args) -> None:
        for m in self.monitors:
            fn = getattr(m, hook, None)
            if fn is not None:
                fn(self, *args)

    # --------------------------------------------------------------- step
    def stable_dt(self) -> tuple[float, int, object]:
        """Smallest stable step, the controlling item and its part."""
        dt, k, which = np.inf, 0, None
        for part in self.parts:
            d, i = part.stable_dt()
            if d < dt or which is None:
                dt, k, which = d, i, part
        for inter in self.interactions:
            dt = min(dt, inter.stable_dt())
        return min(dt, self.dt_max), k, which

    def _sums(self, key: str, n: int) -> np.ndarray:
        sums = self._kick_sums.get(key)
        if sums is None or sums.shape[0] <= n // KICK_BLOCK:
            sums = self._kick_sums[key] = kick_scratch(n)
        return sums

    def _interaction_forces(self, dt: float) -> None:
        for part in self.parts:
            part.kin.a_ext[:] = 0.0
        books = self.books
        if books is not None:
            books.clear_events()
        for inter in self.interactions:
            tracked = books is not None and books.tracks(inter.name)
            if tracked:
                books.before()
            inter.forces(self.t, dt, inter.part.kin.a_ext)
            if tracked:
                books.after(inter.name)
        for part in self.parts:
            part.kin.a += part.kin.a_ext
        if self.mass_scaling is not None:
            self.mass_scaling.scale()

    def step(self, t_stop: float | None = None) -> None:
        """Advance one step; ``t_stop`` shortens it so that the run ends there."""
        dt, k, part = self.stable_dt()
        self._notify("before_step", dt, k, part)
        # interactions get the stable step, not one shortened to end the run:
        # a penalty spring k = alpha m / dt^2 (paper eq. 8) would grow by
        # (dt / dt_short)^2
        self.dt_stable = dt
        if t_stop is not None and self.t + dt > t_stop:
            dt = max(t_stop - self.t, 0.0)
        dt_kick = 0.5 * dt if self.step_count == 0 else 0.5 * (self.dt_prev + dt)
        for inter in self.interactions:
            inter.prescribe(self.t, dt)
        ke = wc = we = None
        for part in self.parts:
            kp = wp = 0.0
            for j, q in enumerate(dofs(part)):
                k_, c_, e_ = kick(q.v, q.a, q.a_ext, q.inertia(), q.bc, q.bc_v, dt_kick,
                                  q.v_mid, self._sums(f"{part.name}.{j}", q.n))
                ke, wc, we = _add(ke, k_), _add(wc, c_), _add(we, e_)
                kp += k_
                wp += c_ + e_
            self.part_kinetic[part.name] = kp
            self.part_work[part.name] += wp
            if self.step_count == 0:
                self.part_start[part.name] = kp + part.energies()[0]
        self.work_contact += wc
        self.work_external += we
        self.kinetic, self.dt_step = ke, dt
        if self.books is not None:
            self.books.book(dt_kick)
        for inter in self.interactions:
            inter.after_kick(dt_kick)
            w = inter.external_work()  # (gravity) external, not an interaction's
            self.work_contact -= w
            self.work_external += w
        for inter in self.interactions:
            inter.constrain(self.t, dt)
        self._notify("after_kick")

        for part in self.parts:
            part.drift(dt)
        self.t += dt
        self.step_count += 1
        self.dt_prev = dt
        for part in self.parts:
            part.update_geometry(self.t, dt)
        for inter in self.interactions:
            inter.update_geometry(self.t)
        for part in self.parts:
            part.internal_forces(self.t, dt)
        self._interaction_forces(self.dt_stable)
        if self.books is not None and self.events:
            self.books.before()
        for event in self.events:
            if event.due(self):
                event.apply(self)
        if self.books is not None and self.events:
            self.books.after(InteractionWork.EVENTS)
        self._notify("after_step")

    # ------------------------------------------------------------ records
    def record(self, kinetic: float | None = None, dt: float | None = None) -> dict:
        """Energy balance (J, J/m in 2D) and the parts' and interactions' columns.

        At the last kick's time by default (``kinetic`` and ``dt`` of that
        kick); the run's final row passes the kinetic energy of the current
        velocities.
        """
        kinetic = self.kinetic if kinetic is None else kinetic
        ie = iav = None
        for part in self.parts:
            a, b = part.energies()
            ie, iav = _add(ie, a), _add(iav, b)
        e_contact = -self.work_contact
        items = (*self.parts, *self.interactions, *self.events)
        removed, released = _book(items, "energy_removed"), _book(items, "energy_released")
        e_removed = 0.0 if removed is None else removed
        e_chemical = 0.0 if released is None else released
        rec = {
            "time": self.t, "step": float(self.step_count),
            "dt": self.dt_step if dt is None else dt,
            "E_kinetic": kinetic, "E_internal": ie, "E_viscous": iav,
            "E_contact": e_contact, "W_external": self.work_external,
            "E_total": (kinetic + ie + e_contact - self.work_external + e_removed
                        - e_chemical),
            # how quasi-static the run is: small (< 0.05 say) for a static answer
            "KE_IE_ratio": kinetic / ie if ie > 0.0 else 0.0,
        }
        if removed is not None:
            rec["E_removed"] = e_removed
        if released is not None:
            rec["E_chemical"] = e_chemical
        for part in self.parts:
            rec.update(part.columns())
        for inter in self.interactions:
            rec.update(inter.columns(self.t))
        for ev in self.events:
            if hasattr(ev, "columns"):
                rec.update(ev.columns(self.t))
        if self.books is not None:
            rec.update(self.books.columns())
        if self.mass_scaling is not None:
            rec.update(self.mass_scaling.columns())
        return rec

    def kinetic_now(self) -> float:
        """Kinetic energy of the current (mid-step) velocities [J] (slaves of
        tied and hybrid couplings left out: their masters carry their mass)."""
        return float(sum(0.5 * np.sum(np.where(q.bc == BC_SLAVE, 0.0, q.inertia())
                                      * np.sum(q.v * q.v, axis=1))
                         for p in self.parts for q in dofs(p)))

    # --------------------------------------------------------- checkpoint
    def state(self) -> tuple[dict, dict[str, dict[str, np.ndarray]]]:
        """Scalars and array groups of a checkpoint (parts, interactions, events)."""
        scalars = {"t": self.t, "step": self.step_count, "dt_prev": self.dt_prev,
                   "dt0": self.dt0, "dt_stable": self.dt_stable,
                   "dt_step": self.dt_step, "work_contact": self.work_contact,
                   "work_external": self.work_external}
        groups = {}
        for kind, items in (("part", self.parts), ("interaction", self.interactions)):
            for item in items:
                sc, arrays = item.state()
                scalars.update({f"{kind}.{item.name}.{k}": v for k, v in sc.items()})
                groups[f"{kind}.{item.name}"] = arrays
        for ev in self.events:
            scalars.update({f"event.{ev.name}.{k}": v for k, v in ev.state().items()})
        for part in self.parts:
            scalars[f"energy.part.{part.name}.work"] = self.part_work[part.name]
            scalars[f"energy.part.{part.name}.kinetic"] = self.part_kinetic[part.name]
            if part.name in self.part_start:
                scalars[f"energy.part.{part.name}.start"] = self.part_start[part.name]
            groups[f"kin.{part.name}"] = part.kin.arrays()
            if len(dofs(part)) > 1:
                groups[f"rot.{part.name}"] = part.kin.rot.arrays()
        if self.books is not None:
            sc, groups["interaction_work"] = self.books.state()
            scalars.update({f"books.{k}": v for k, v in sc.items()})
        return scalars, groups

    def restore(self, scalars: dict, groups: dict) -> None:
        """Continue from :meth:`state` (bitwise identical continuation).

        Parts grown by events during the run are grown to the checkpoint's
        size first (the listeners run after the arrays are restored).
        """
        for part in self.parts:
            if f"kin.{part.name}" not in groups:
                raise ValueError(f"the checkpoint has no part {part.name!r}: it was written "
                                 "by another deck; run the deck again")
            arrays = groups[f"kin.{part.name}"]
            q = part.kin
            n_old, n_new = q.n, arrays["x"].shape[0]
            if n_new < n_old:
                raise ValueError(f"checkpoint has {n_new} items in part {part.name!r}, "
                                 f"the model {n_old}: it was written by another deck")
            if n_new > n_old:
                q.grow(n_new - n_old, notify=False)
            for name, arr in arrays.items():
                setattr(q, name, arr)  # a shape that does not fit raises
            if n_new > n_old:
                q.notify_grown(n_old, n_new)
            if len(dofs(part)) > 1:
                for name, arr in groups[f"rot.{part.name}"].items():
                    setattr(q.rot, name, arr)
        self.t = float(scalars["t"])
        self.step_count = int(scalars["step"])
        self.dt_prev = float(scalars["dt_prev"])
        self.dt0 = float(scalars["dt0"])
        self.dt_stable = float(scalars["dt_stable"])
        self.dt_step = float(scalars["dt_step"])
        self.work_contact = float(scalars["work_contact"])
        self.work_external = float(scalars["work_external"])
        for part in self.parts:  # (absent in checkpoints before issue 57: zero)
            pre = f"energy.part.{part.name}."
            self.part_work[part.name] = float(scalars.get(pre + "work", 0.0))
            self.part_kinetic[part.name] = float(scalars.get(pre + "kinetic", 0.0))
            if pre + "start" in scalars:
                self.part_start[part.name] = float(scalars[pre + "start"])
        for kind, items in (("part", self.parts), ("interaction", self.interactions)):
            for item in items:
                item.restore(*_own_state(scalars, groups, f"{kind}.{item.name}"))
        for ev in self.events:
            ev.restore(_own_state(scalars, groups, f"event.{ev.name}")[0])
        # what interactions report (counts, totals) is evaluated again into
        # scratch arrays (the accelerations themselves are in the checkpoint);
        # an evaluation may also move an interaction's own state (a penalty
        # spring's allowance, a contact's), which the checkpoint holds as the
        # run had it, so that state is put back after it
        scratch = {id(p.kin): np.zeros_like(p.kin.a_ext) for p in self.parts}
        for inter in self.interactions:
            inter.forces(self.t, self.dt_stable, scratch[id(inter.part.kin)])
            inter.restore(*_own_state(scalars, groups, f"interaction.{inter.name}"))
        if self.books is not None:
            self.books.restore(_own_state(scalars, groups, "books")[0],
                               groups.get("interaction_work", {}))
        if self.mass_scaling is not None:  # the restored masses' inertia
            self.mass_scaling.refresh()
