r"""Element erosion: failed elements leave a mesh, deleted or turned into SPH particles.

Thesis section 5.3: elements that fail are, in LS-DYNA's plain erosion,
deleted with their mass and energy; the thesis proposes to turn them into SPH
particles instead, which keep the mass, momentum and energy and go on
carrying load in compression. The event checks the rules of
:mod:`sphdyn.parts.fem.erosion_criteria` after every ``every``-th step and
takes the flagged elements out (:meth:`~sphdyn.parts.fem.SolidPart.erode`).

**Into particles** (``to = "particles"``): one particle at the element's
centre (``per_element = 1``) or one per octant (``8``; 4 quadrants in 2D) at
the parent points :math:`\xi_o = \pm\tfrac12`, each with

* mass :math:`m_e / n_p` and velocity :math:`\mathbf v_o = \sum_I
  N_I(\xi_o)\mathbf v_I`: as :math:`\sum_o N_I(\xi_o) = n_p/n_{en}`, the
  particles carry exactly the momentum :math:`\sum_I (m_e/n_{en})\mathbf
  v_I` the nodes lose;
* the element's stress, damage and history (the mean of its integration
  points), its density :math:`m_e/V_e`, the material's reference density
  and a nominal volume :math:`m/\rho_0`, smoothing length ``h_factor``
  times :math:`(V_e/n_p)^{1/d}`, with :math:`V_e` at least
  :data:`MIN_VOLUME_RATIO` times its initial volume (a crushed or inverted
  element);
* specific internal energy: the element's (its points' work and its
  hourglass work per unit mass) plus the kinetic energy of the nodes'
  relative motion, :math:`\sum_I \tfrac12 \tfrac{m_e}{n_{en}}|\mathbf v_I|^2
  - \sum_o \tfrac12\tfrac{m_e}{n_p}|\mathbf v_o|^2 \ge 0` (Jensen), which
  the particles cannot carry as motion: so the total energy is kept exactly
  at the velocities of the conversion.

The new particles join their material's group of the SPH part, in the body
``body`` (an updated-Lagrangian body), and meet the remaining elements
through any penalty coupling of the two parts, whose master faces follow
the erosion (:meth:`~sphdyn.interactions.PenaltyCoupling.mesh_changed`);
that coupling's forces of the step are taken out of the accelerations
before anything below reads them and those of the new surface put back
after (:meth:`~sphdyn.interactions.PenaltyCoupling.withdraw_forces`), so the
particles inherit no contact force from their element's nodes.
A degenerate element (eroded by the time-step rule, crushed below
:data:`MIN_VOLUME_RATIO` of its volume, or inverted) gives no force in the
step it fails in (LS-DYNA's practice; its last force is the artefact it
fails for): its nodal forces leave its nodes' accelerations first
(:meth:`~sphdyn.parts.fem.SolidPart.withdraw_forces`; they sum to zero, so
the momentum rate is unchanged), and their work over the coming half kick,
:math:`\tfrac{\Delta t}2\sum_I \mathbf f_{eI}\cdot\mathbf v_I`, goes with
its internal energy (which holds that half step's work of its stress). An element
eroded at a sane shape keeps its loads for the step. Until the next step
computes their forces, the particles' acceleration is then the one their
element's nodes have there, :math:`\sum_I N_I(\xi_o)\mathbf a_I`: the
nodes keep theirs, so the rate of momentum of nodes and particles is that of
the nodes before (:math:`\sum_o N_I(\xi_o)\, m_e/n_p = m_e/n_{en}`). The
energies moved and removed are taken at the velocities after the coming
half kick, :math:`\mathbf v + \tfrac{\Delta t}2\mathbf a`, where the
stepper books its kinetic energy.

**Deleted** (``to = "nothing"``, LS-DYNA's plain erosion): the mass, the
kinetic energy of the nodes' shares and the internal energy leave the model;
the history reports them (``m_eroded_<mesh>``, ``E_eroded_<mesh>``) and the
energy balance counts the removed energy (``E_removed``), so ``E_total``
still closes.

The model and its tests: docs/theory.md, "Element erosion".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..deck.sections.sph import Sph
from ..geometry.shapes import corner_signs, shape_functions
from ..parts.fem.erosion_criteria import (BY_TIME_STEP, REASONS, erosion_flags,
                                          reference_gradients)
from ..parts.fem.solid import block_scratch
from ..state import BC_FREE

TARGETS = ("particles", "nothing")
#: the smallest volume ratio V/V0 a particle's density and size are taken at: an
#: element crushed below half its volume (or inverted, V <= 0) is a numerical
#: artefact (concrete compacts by a few per cent), and m/V of it gave debris
#: particles a negative or huge density and a NaN size
MIN_VOLUME_RATIO = 0.5


@dataclass(frozen=True)
class ErosionRules:
    """The erosion rules of one material (None: the rule is off).

    erode : LS-DYNA MAT_159's ERODE (> 1): damage above 0.99 and maximum
        principal strain above ``erode - 1``; only for a material with damage.
    principal_strain : maximum principal (engineering) strain.
    effective_strain : effective (von Mises, logarithmic) strain.
    min_time_step : the element's stable step [s] below which it erodes.
    """

    erode: float | None = None
    principal_strain: float | None = None
    effective_strain: float | None = None
    min_time_step: float | None = None

    def __post_init__(self):
        if self.erode is not None and not self.erode > 1.0:
            raise ValueError(f"erode must be > 1 (MAT_159's ERODE), got {self.erode}")
        for key in ("principal_strain", "effective_strain", "min_time_step"):
            value = getattr(self, key)
            if value is not None and not value > 0.0:
                raise ValueError(f"{key} must be > 0, got {value}")

    @property
    def any(self) -> bool:
        return any(v is not None for v in (self.erode, self.principal_strain,
                                            self.effective_strain, self.min_time_step))

    def row(self) -> np.ndarray:
        """The rule table row of :func:`~sphdyn.parts.fem.erosion_criteria.erosion_flags`."""
        off = np.inf
        return np.array([off if self.erode is None else self.erode - 1.0,
                         off if self.principal_strain is None else self.principal_strain,
                         off if self.effective_strain is None else self.effective_strain,
                         0.0 if self.min_time_step is None else self.min_time_step])


class ElementErosion:
    """Erosion of the elements of one solid part (module docstring).

    Parameters
    ----------
    name : the event's name.
    solid : the :class:`~sphdyn.parts.fem.SolidPart`.
    rules : material index -> :class:`ErosionRules` (materials not listed
        do not erode).
    to : ``"particles"`` or ``"nothing"``.
    per_element : 1 or 8 particles per element (4 in 2D for 8).
    sph : the SPH part that takes the particles (``to = "particles"``).
    body : the particles' body index in ``sph``.
    h_factor : smoothing length over particle size (default: the deck's
        ``[sph] h_factor``).
    every : check every this many steps.
    """

    def __init__(self, name: str, solid, rules: dict, to: str = "particles",
                 per_element: int = 1, sph=None, body: int = 0,
                 h_factor: float = Sph.model_fields["h_factor"].default,
                 every: int = 1):
        if to not in TARGETS:
            raise ValueError(f"{name}: to must be one of {TARGETS}, got {to!r}")
        if per_element not in (1, 8):
            raise ValueError(f"{name}: per_element must be 1 or 8, got {per_element}")
        if to == "particles" and sph is None:
            raise ValueError(f"{name}: erosion into particles needs an SPH part")
        if every < 1:
            raise ValueError(f"{name}: every must be >= 1, got {every}")
        self.name, self.solid, self.to, self.sph = name, solid, to, sph
        self.body, self.h_factor, self.every = int(body), float(h_factor), int(every)
        dim = solid.dim
        self.xi = (np.zeros((1, dim)) if per_element == 1 else 0.5 * corner_signs(dim))
        self.N = shape_functions(dim, self.xi)  # (n_p, nen)
        el = solid.el
        table = np.tile(ErosionRules().row(), (el.n, 1))
        for mat, r in rules.items():
            group = next((g for g in solid.groups if g.material == mat), None)
            if r.erode is not None and group is not None and not group.model.has_damage:
                raise ValueError(f"{name}: material {mat} ('{group.model.name}') has no "
                                 "damage variable, so the damage rule (erode) cannot apply; "
                                 "use principal_strain or effective_strain")
            table[el.mat == mat] = r.row()
        self.rules = table
        self.b0 = np.zeros((el.n, el.nen, 3))
        reference_gradients(solid.nodes.x0, el.conn, dim, solid.tab, self.b0)
        self.flags = np.zeros(el.n, dtype=np.int8)
        self.work = block_scratch(el.n, 1, 0)  # a 3 x 3 slab per block (F)
        self.count = {reason: 0 for reason in REASONS.values()}
        self.eroded = 0
        self.born = 0
        self.mass_removed = 0.0
        self.energy_removed = 0.0  # counted in the stepper's E_total (module docstring)
        self.energy_to_heat = 0.0  # the nodes' relative kinetic energy given to particles

    # ----------------------------------------------------------- protocol
    def due(self, stepper) -> bool:
        return stepper.step_count % self.every == 0

    def apply(self, stepper) -> None:
        s, el, pts = self.solid, self.solid.el, self.solid.pts
        n = erosion_flags(s.nodes.x, el.conn, el.active, self.b0, s.dim, pts.damage, s.ngp,
                          el.dt_el, s.s.cfl, self.rules, self.flags, self.work)
        if n == 0:
            return
        new = np.flatnonzero(self.flags).astype(np.int64)
        for code in np.unique(self.flags[new]):
            self.count[REASONS[int(code)]] += int(np.sum(self.flags[new] == code))
        dt_half = 0.5 * stepper.dt_prev  # the coming half kick
        couplings = [inter for inter in stepper.interactions
                     if getattr(inter, "solid", None) is s and hasattr(inter, "mesh_changed")]
        for inter in couplings:  # the contact forces of the old surface out (of the books too)
            if hasattr(inter, "withdraw_forces"):
                inter.withdraw_forces()
        # a degenerate element (its step collapsed, crushed below
        # MIN_VOLUME_RATIO or inverted) gives no force in its last step: that
        # force is the artefact it fails for; the work its loads would have
        # done over the coming half kick stays in its energy
        # (SolidPart.withdraw_forces: first order, the books' own accuracy)
        degenerate = new[(self.flags[new] == BY_TIME_STEP)
                         | (el.vol[new] < MIN_VOLUME_RATIO * el.vol0[new])]
        held = s.withdraw_forces(degenerate, dt_half)
        m, kinetic, internal = s.element_books(new, dt_half)
        internal[np.searchsorted(new, degenerate)] += held
        born = (self._particles(new, dt_half, kinetic, internal) if self.to == "particles"
                else None)
        s.erode(new)
        self.eroded += new.size
        if born is None:
            self.mass_removed += float(m.sum())
            self.energy_removed += float(kinetic.sum() + internal.sum())
        for inter in couplings:  # the new surface and its forces
            inter.mesh_changed()
        if born is not None:
            self._add(born)

    def _particles(self, new: np.ndarray, dt_half: float, kinetic: np.ndarray,
                   internal: np.ndarray):
        """The particles of the elements ``new`` (k,), read before they erode;
        ``kinetic`` and ``internal`` (k,) their books
        (:meth:`~sphdyn.parts.fem.SolidPart.element_books`)."""
        s, el, pts, q = self.solid, self.solid.el, self.solid.pts, self.solid.nodes
        k, npp, dim = new.size, self.N.shape[0], s.dim
        conn = el.conn[new]
        at = lambda a: np.einsum("on,knd->kod", self.N, a[conn]).reshape(-1, 3)  # noqa: E731
        x, v, acc, acc_ext = at(q.x), at(q.v), at(q.a), at(q.a_ext)
        m_el = el.m[new]
        # kinetic energy after the coming half kick (the stepper's book)
        vp = (v + dt_half * acc).reshape(k, npp, 3)
        ke_parts = 0.5 * (m_el / npp) * np.sum(vp * vp, axis=(1, 2))
        relative = np.maximum(kinetic - ke_parts, 0.0)
        self.energy_to_heat += float(relative.sum())
        ip = s.element_points(new)  # (k, ngp)
        mean = lambda a: a[ip].mean(axis=1)  # noqa: E731
        e_el = (internal + relative) / m_el
        rep = lambda a: np.repeat(a, npp, axis=0)  # noqa: E731
        vol = np.maximum(el.vol[new], MIN_VOLUME_RATIO * el.vol0[new])  # crushed or inverted
        return dict(x=x, v=v, a=acc, a_ext=acc_ext, m=rep(m_el / npp),
                    rho=rep(m_el / vol),
                    rho0=rep(mean(pts.rho0)), size=rep((vol / npp) ** (1.0 / dim)),
                    e=rep(e_el), e_av=rep(mean(pts.e_av)), sig=rep(mean(pts.sig)),
                    damage=rep(mean(pts.damage)), hist=rep(mean(pts.hist)),
                    c=rep(pts.c[ip].max(axis=1)), mat=rep(pts.mat[ip[:, 0]]))

    def _add(self, f: dict) -> None:
        """Append the particles ``f`` to the SPH part (its listeners rebuild)."""
        p = self.sph.p
        k = f["x"].shape[0]
        rows = p.grow(k, notify=False)
        p.place(rows, x=f["x"], v=f["v"], m=f["m"], vol0=f["m"] / f["rho0"],
                rho0=f["rho0"], rho=f["rho"], h=self.h_factor * f["size"],
                mat=f["mat"], body=self.body)
        p.a[rows] = f["a"]
        p.a_ext[rows] = f["a_ext"]
        p.bc[rows] = BC_FREE
        p.bc_v[rows] = 0.0
        p.active[rows] = 1
        p.e[rows] = f["e"]
        p.e_av[rows] = f["e_av"]
        p.sig[rows] = f["sig"]
        p.L[rows] = 0.0
        p.c[rows] = f["c"]
        p.damage[rows] = f["damage"]
        p.hist[rows] = 0.0  # the element's history, column by column by name
        for col, name in enumerate(self.solid.pts.hist_names):
            p.hist[rows, p.hist_names.index(name)] = f["hist"][:, col]
        p.notify_grown(rows.start, rows.stop)
        self.born += k

    def columns(self, t: float) -> dict[str, float]:
        """``eroded_<mesh>``, per rule ``eroded_<mesh>_<rule>``, and
        ``particles_from_<mesh>`` or ``m_eroded_<mesh>`` and ``E_eroded_<mesh>``."""
        mesh = self.solid.name
        out = {f"eroded_{mesh}": float(self.eroded)}
        out.update({f"eroded_{mesh}_{k}": float(v) for k, v in self.count.items()})
        if self.to == "particles":
            out[f"particles_from_{mesh}"] = float(self.born)
        else:
            out[f"m_eroded_{mesh}"] = self.mass_removed
            out[f"E_eroded_{mesh}"] = self.energy_removed
        return out

    # --------------------------------------------------------- checkpoint
    def state(self) -> dict:
        out = {"eroded": self.eroded, "born": self.born, "mass_removed": self.mass_removed,
               "energy_removed": self.energy_removed, "energy_to_heat": self.energy_to_heat}
        out.update({f"count_{k}": v for k, v in self.count.items()})
        return out

    def restore(self, scalars: dict) -> None:
        self.eroded = int(scalars.get("eroded", 0))
        self.born = int(scalars.get("born", 0))
        self.mass_removed = float(scalars.get("mass_removed", 0.0))
        self.energy_removed = float(scalars.get("energy_removed", 0.0))
        self.energy_to_heat = float(scalars.get("energy_to_heat", 0.0))
        for k in self.count:
            self.count[k] = int(scalars.get(f"count_{k}", 0))
