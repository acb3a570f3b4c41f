r"""Selective mass scaling: inertia added where it limits the time step.

An explicit step is limited by its fastest item: in a reinforced-concrete
model the steel of the bars (their sublayer particles or elements), in a
mesh its smallest element. LS-DYNA's ``*CONTROL_TIMESTEP`` with ``DT2MS <
0`` adds mass to exactly those items, so that each one's stable step
reaches a target :math:`\Delta t^*`, and leaves the others alone. The
frequencies of an item scale as :math:`1/\sqrt{m}`, so an item of step
:math:`\Delta t_e < \Delta t^*` needs the factor

.. math:: f_e = (\Delta t^* / \Delta t_e)^2, \qquad \Delta m_e = (f_e - 1)\, m_e

(Olovsson, Simonsson & Unosson 2005, "Selective mass scaling for explicit
finite element analyses", Int. J. Numer. Meth. Engng 63, sec. 1, the
conventional form; LS-DYNA Keyword Manual, ``*CONTROL_TIMESTEP``, DT2MS).

Each part decides how its items take the mass (``part.scale_mass(target)``,
returning the added mass per row of each of its tables): a particle its own
(:meth:`sphdyn.parts.sph.part.SPHPart.scale_mass`, the CFL step with the
wave speed times :math:`r_i = 1/\sqrt{f_i}`), an element shared by its
nodes as its own mass is (:meth:`~sphdyn.parts.fem.solid_part.SolidPart.scale_mass`,
and bar and beam elements with their rotary inertia,
:meth:`~sphdyn.parts.fem.line_part.LinePart.scale_mass`). A slave of a
coupling (tied, hybrid, embedded, sublayer) has no inertia of its own: its
added mass goes to the items it follows, with the weights its own mass went
with (``interaction.slave_map()``).

The added mass has inertia only. Every force is computed as without it
(the SPH densities and stresses from the particles' own masses, the
contact stiffness, gravity's weight); the stepper then divides the
accelerations by the inertia instead of the mass,

.. math:: \mathbf a_i \leftarrow \frac{m_i}{m_i + \Delta m_i}\,\mathbf a_i ,

and the kick books the kinetic energy :math:`\tfrac12 (m_i + \Delta
m_i)|\mathbf v_i|^2` and the work of the interaction and boundary forces
with the same inertia, so the energy balance holds with the added mass in
it. The mass is added once, at the start (LS-DYNA's ``MS1ST``): a step that
falls below the target later (a crushed element, a particle compressed to a
higher sound speed) is taken as it is.

The price: a wave crosses a scaled item slower by :math:`\sqrt{f}`, and the
added mass takes part in the motion (a bar's inertia in a beam's
vibration). ``max_added`` bounds it as a fraction of the model's mass (as
LS-DYNA's reports of the added mass are); the summary and the history
report it per part (``mass_added_<part>`` [kg], kg/m in 2D).

The model and its tests: docs/theory.md, "Selective mass scaling".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .state import BC_SLAVE, STATE


@njit(cache=True, error_model="numpy", parallel=True)
def inertia_accelerations(m, m_added, m_inertia, a, a_ext):
    r"""The inertia :math:`M_i = m_i + \Delta m_i` into ``m_inertia`` and the
    accelerations of the forces :math:`m_i\mathbf a_i` turned into those of the
    inertia, :math:`\mathbf a_i \leftarrow (m_i / M_i)\,\mathbf a_i` (and
    ``a_ext``, the interactions' part of ``a``, alike). Massless items are left
    alone. ``m``, ``m_added``, ``m_inertia`` (N,) [kg]; ``a``, ``a_ext`` (N, 3)
    [m/s^2] in place."""
    for i in prange(m.shape[0]):
        mi = m[i] + m_added[i]
        m_inertia[i] = mi
        if mi > 0.0 and m_added[i] != 0.0:
            s = m[i] / mi
            for d in range(3):
                a[i, d] *= s
                a_ext[i, d] *= s


def _round_down(x: float, digits: int = 6) -> float:
    """``x`` > 0 rounded down to ``digits`` significant digits (a limit printed
    so that the printed value still keeps within it)."""
    scale = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(np.floor(x / scale) * scale)


def _tables(part) -> dict:
    """A part's degree-of-freedom tables by name: ``kin`` and (beams) ``rot``."""
    rot = getattr(part.kin, "rot", None)
    return {"kin": part.kin} if rot is None else {"kin": part.kin, "rot": rot}


class MassScaling:
    """Selective mass scaling of a stepper's parts to the step ``target`` [s],
    refused when it would add more than ``max_added`` times the model's mass.

    :meth:`apply` (the stepper calls it once its parts have started) adds the
    mass; :meth:`scale` (after every force evaluation) turns the accelerations
    into those of the inertia; :meth:`columns` and :meth:`summary` report it.
    """

    def __init__(self, target: float, max_added: float = 0.02, select: dict | None = None):
        if not target > 0.0:
            raise ValueError(f"the mass-scaling target step must be > 0, got {target}")
        if not max_added > 0.0:
            raise ValueError(f"max_added must be > 0, got {max_added}")
        self.target = float(target)
        self.max_added = float(max_added)
        #: part name -> False (left alone), True (all its items) or an (N,) bool
        #: mask of its items (particles); None: every item of every part
        self.select = select
        self.parts: list = []
        self.scaled: list = []  # the tables with added mass (each has m_added)
        self.added0: dict[str, float] = {}  # mass added to each part at the start [kg]
        #: the model's first step without and with the added mass [s] (the stepper's)
        self.steps: tuple[float, float] | None = None

    # ----------------------------------------------------------- the mass
    def _added(self, parts, interactions, target: float) -> dict[int, np.ndarray]:
        """Added mass per row of every table (keyed by ``id(table)``) for
        ``target``; sets the parts' step factors for it."""
        added: dict[int, np.ndarray] = {}
        for part in parts:
            chosen = True if self.select is None else self.select.get(part.name, False)
            if chosen is False:
                continue
            fn = getattr(part, "scale_mass", None)
            if fn is None:
                raise ValueError(f"part '{part.name}' ({part.kind}) cannot be mass-scaled: "
                                 "leave it out of time.mass_scaling.parts")
            tables = _tables(part)
            mask = None if chosen is True else np.asarray(chosen, dtype=bool)
            for name, arr in fn(target, mask).items():
                added[id(tables[name])] = np.asarray(arr, dtype=float)
        for inter in interactions:
            fn = getattr(inter, "slave_map", None)
            if fn is None:
                continue
            slaves, rows, masters, conn, weights = fn()
            extra = added.get(id(slaves))
            if extra is None or not np.any(extra[rows]):
                continue
            into = added.setdefault(id(masters), np.zeros(masters.n))
            np.add.at(into, np.asarray(conn).ravel(),
                      (np.asarray(weights) * extra[rows][:, None]).ravel())
            extra[rows] = 0.0
        return added

    def _fractions(self, parts, added) -> dict[str, tuple[float, float]]:
        """Per part: (added mass, its own mass) [kg] of its translations, slaves
        (whose mass their masters carry) left out."""
        out = {}
        for part in parts:
            q = part.kin
            own = q.bc != BC_SLAVE
            extra = added.get(id(q))
            out[part.name] = (0.0 if extra is None else float(extra[own].sum()),
                              float(q.m[own].sum()))
        return out

    def _worst(self, fractions) -> tuple[str, float, float, float]:
        """(the part given the most mass, its added and own mass [kg], the added
        mass over the whole model's mass)."""
        name = max(fractions, key=lambda k: fractions[k][0])
        total = sum(m for _, m in fractions.values())
        added = sum(dm for dm, _ in fractions.values())
        dm, m = fractions[name]
        return name, dm, m, added / max(total, 1e-300)

    def apply(self, parts, interactions) -> None:
        """Add the mass (module docstring); refuse a target that needs more than
        ``max_added`` of the model's mass, naming the part given the most and the
        largest target within the limit."""
        parts, interactions = list(parts), list(interactions)
        added = self._added(parts, interactions, self.target)
        name, dm, m, frac = self._worst(self._fractions(parts, added))
        if frac > self.max_added:
            lo, hi = 0.0, self.target  # the largest target within the limit
            for _ in range(40):
                mid = 0.5 * (lo + hi)
                f = self._worst(self._fractions(parts, self._added(parts, interactions,
                                                                    mid)))[3]
                lo, hi = (mid, hi) if f <= self.max_added else (lo, mid)
            self._added(parts, interactions, 1e-300)  # the parts' factors back to 1
            lo = _round_down(lo)
            raise ValueError(
                f"mass scaling to a step of {self.target:.4g} s would add {100 * frac:.3g} % "
                f"to the model's mass, above time.mass_scaling.max_added = "
                f"{self.max_added:g}; the most, {dm:.4g} kg, to part '{name}' ({m:.4g} kg "
                f"of its own): lower the target (at most {lo:.6g} s keeps within the "
                "limit) or raise max_added")
        self.parts = parts
        self.scaled = []
        for part in parts:
            for q in _tables(part).values():
                extra = added.get(id(q))
                if extra is None or not np.any(extra):
                    continue
                q.add("m_added", (), np.float64, kind=STATE)
                q.add("m_inertia", (), np.float64)
                q.m_added = extra
                self.scaled.append(q)
        self.refresh()
        self.added0 = {k: v[0] for k, v in self._fractions(parts, added).items()}

    def refresh(self) -> None:
        """The inertia of the current masses (after a restart restored them)."""
        for q in self.scaled:
            np.add(q.m, q.m_added, out=q.m_inertia)

    def scale(self) -> None:
        """Turn the accelerations of the forces into those of the inertia."""
        for q in self.scaled:
            inertia_accelerations(q.m, q.m_added, q.m_inertia, q.a, q.a_ext)

    # ---------------------------------------------------------- reporting
    def columns(self) -> dict[str, float]:
        """``mass_added_<part>``: the mass added to each part [kg] (its
        translations; a coupling's slaves' share is on their masters)."""
        out = {}
        for part in self.parts:
            q = part.kin
            out[f"mass_added_{part.name}"] = (
                float(q.m_added[q.bc != BC_SLAVE].sum()) if "m_added" in q.names() else 0.0)
        return out

    def summary(self) -> dict:
        """The target, the added mass's share of the model's mass, and per part the
        added mass [kg], its share of the part's own mass and the items whose step
        factor is above 1."""
        parts = {}
        for part in self.parts:
            q = part.kin
            own = q.bc != BC_SLAVE
            m = float(q.m[own].sum())
            dm = self.added0.get(part.name, 0.0)
            parts[part.name] = {"added_kg": dm, "fraction": dm / m if m > 0 else 0.0,
                                "items_scaled": int(_scaled_items(part))}
        total = sum(float(p.kin.m[p.kin.bc != BC_SLAVE].sum()) for p in self.parts)
        added = sum(v["added_kg"] for v in parts.values())
        out = {"target": self.target, "max_added": self.max_added,
               "fraction": added / total if total > 0 else 0.0, "parts": parts}
        if self.steps is not None:
            out["dt_without"], out["dt_with"] = self.steps
        return out

    def describe(self) -> str:
        """One paragraph for ``sphdyn check``: the step's gain and what it costs."""
        sm = self.summary()
        lines = [f"  mass scaling to {self.target:.4g} s: adds {100 * sm['fraction']:.3g} % "
                 f"of the model's mass (limit {100 * self.max_added:.3g} %)"]
        if self.steps is not None:
            a, b = self.steps
            lines[0] += f"; first step {a:.4g} s -> {b:.4g} s ({b / a:.3g}x fewer steps)"
        for name, v in sm["parts"].items():
            if v["added_kg"] > 0.0:
                lines.append(f"    part '{name}': +{v['added_kg']:.4g} kg "
                             f"({100 * v['fraction']:.3g} % of its own)")
        return "\n".join(lines)


def _scaled_items(part) -> int:
    """The part's particles or elements with a mass-scaling factor other than 1."""
    p = getattr(part, "p", None)
    if p is not None and "c_mass" in p.names():
        return int(np.count_nonzero(p.c_mass != 1.0))
    el = getattr(part, "el", None)
    if el is None:
        el = getattr(part, "elements", None)
    return 0 if el is None else int(np.count_nonzero(el.dt_mass != 1.0))
