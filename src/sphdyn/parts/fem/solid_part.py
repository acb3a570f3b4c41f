"""The solid finite-element part: hex8 (3D) or quad4 (2D plane strain) elements.

One step of the part (the stepper calls these in order; state at
:math:`t^n`: :math:`\\mathbf x^n, \\mathbf v^{n-1/2}, \\sigma^n, \\mathbf a^n`):

1. :meth:`SolidPart.drift`: nodes to :math:`\\mathbf x^{n+1}`;
2. :meth:`SolidPart.internal_forces`: velocity gradient on the mid-step
   geometry, geometry at :math:`n+1` (:mod:`.solid`), the material update of
   every group (the same group kernels as the particles,
   :mod:`sphdyn.materials`: Jaumann-rotated hypoelastic, J2 or CSCM), then the
   element nodal forces (stress, bulk viscosity, hourglass control) gathered
   into the nodes' ``a``.

Masses are lumped: each node gets ``1/nen`` of the mass of every element it
belongs to. The stable step is the element bound of :mod:`.solid`.

The model and its tests: docs/theory.md, "Solid finite elements".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...deck.sections.meshes import Mesh
from ...geometry.mesh import MESH_KINDS
from ...geometry.shapes import gauss_derivatives, hourglass_vectors, volume_table
from ...integrate import drift, internal_energies, ordered_sum
from ...materials import MaterialGroup, history_layout
from ...fields import von_mises
from ...state import BC_FIXED, STATE, Elements, MaterialPoints, Nodes
from ..base import register_part
from .gather import gather_loads, node_element_list
from .output import mesh_frame, mesh_summary
from .hex_lanes import hex_forces, hex_strain_rate, lane_scratch
from .solid import (DT_BLOCKS, block_scratch, char_length, element_step, element_volumes,
                    local_coordinates, min_time_step, reduced_forces, reduced_strain_rate,
                    uniform_forces, uniform_strain_rate, volume_gradient, weigh_point_work)
from .hourglass import HG_STIFFNESS, HG_VISCOUS, hourglass_bound, hourglass_overlap

INTEGRATIONS = ("one_point", "selective_reduced")
HOURGLASS_FORMS = {"viscous": HG_VISCOUS, "stiffness": HG_STIFFNESS}

#: the deck's [[mesh]] keys: their defaults are the settings' (one home)
DEFAULTS = Mesh.model_fields


@dataclass(frozen=True)
class SolidSettings:
    """Element formulation of a solid part (defaults: LS-DYNA's default solid).

    integration : ``"one_point"`` (uniform strain with hourglass control) or
        ``"selective_reduced"`` (2^d Gauss points, B-bar volumetric part).
    hourglass : ``"viscous"`` or ``"stiffness"`` (Flanagan-Belytschko forms).
    hourglass_coefficient : Q_hg (LS-DYNA's QH; 0.1 by default, 0 switches it off).
    q1, q2 : quadratic and linear bulk-viscosity coefficients (1.5, 0.06).
    cfl : factor on the stable element step (0.9, LS-DYNA's TSSFAC).
    """

    integration: str = DEFAULTS["integration"].default
    hourglass: str = DEFAULTS["hourglass"].default
    hourglass_coefficient: float = DEFAULTS["hourglass_coefficient"].default
    q1: float = DEFAULTS["q1"].default
    q2: float = DEFAULTS["q2"].default
    cfl: float = DEFAULTS["cfl"].default

    def __post_init__(self):
        if self.integration not in INTEGRATIONS:
            raise ValueError(f"integration must be one of {INTEGRATIONS}, "
                             f"got {self.integration!r}")
        if self.hourglass not in HOURGLASS_FORMS:
            raise ValueError(f"hourglass must be one of {tuple(HOURGLASS_FORMS)}, "
                             f"got {self.hourglass!r}")


@register_part("solid")
class SolidPart:
    """Hexahedra (dim 3) or plane-strain quadrilaterals (dim 2) of one mesh.

    Parameters
    ----------
    name : the part's name (history columns and output blocks carry it).
    nodes : :class:`~sphdyn.state.Nodes` with ``x``, ``x0``, ``v``, ``bc``;
        masses are computed here (lumped).
    elements : :class:`~sphdyn.state.Elements` with ``conn`` and ``mat``.
    materials : one ``(model, params)`` per material index used in
        ``elements.mat`` (a dict index -> pair).
    settings : :class:`SolidSettings`.
    """

    def __init__(self, name: str, nodes: Nodes, elements: Elements, materials: dict,
                 settings: SolidSettings = SolidSettings()):
        self.name = name
        self.kin = self.nodes = nodes
        self.el = elements
        self.s = settings
        self.dim = nodes.dim
        kind = {8: "hex8", 4: "quad4"}.get(elements.nen)
        if kind is None or MESH_KINDS[kind][1] != self.dim:
            raise ValueError(f"part {name!r}: {elements.nen}-node elements do not fit "
                             f"dimension {self.dim} (hex8 in 3D, quad4 in 2D)")
        self.element_kind = kind
        self.tab = volume_table(self.dim)
        self.gam = np.ascontiguousarray(hourglass_vectors(self.dim))
        self.dN = np.ascontiguousarray(gauss_derivatives(self.dim))
        self.reduced = settings.integration == "selective_reduced"
        self.ngp = self.dN.shape[0] if self.reduced else 1
        self.hg_form = HOURGLASS_FORMS[settings.hourglass]
        self._dt_t = np.empty(DT_BLOCKS)  # scratch of the parallel stable step
        self._dt_k = np.empty(DT_BLOCKS, dtype=np.int64)
        self.work = block_scratch(elements.n, elements.nen, self.gam.shape[0])
        # one-point hex8: the vectorised passes of .hex_lanes (same bits, faster)
        self.lanes = (lane_scratch(elements.n) if kind == "hex8" and not self.reduced
                      else None)
        nen = elements.nen
        elements.add("fe", (nen, 3))  # element nodal forces, gathered into the nodes
        elements.add("dt_el", ())  # element steps of the last force pass [s]
        if self.reduced:  # the B-bar pass keeps the end-of-step geometry per element
            elements.add("xl", (nen, 3))
            elements.add("g", (nen, 3))
        ne = elements.n
        names, first = history_layout([m for m, _ in materials.values()])
        pts = self.pts = MaterialPoints(ne * self.ngp, len(names))
        pts.elem = np.repeat(np.arange(ne), self.ngp)
        pts.mat = elements.mat[pts.elem]
        if self.reduced:
            pts.add("Bg", (nen, 3))
            pts.add("wg", ())
            pts.add("wm", ())  # the points' mid-step volumes (their work's weights)
            pts.add("e_old", ())  # the specific energies before the material update
        self.groups = []
        for k, (model, params) in sorted(materials.items()):
            idx = np.flatnonzero(pts.mat == k).astype(np.int64)
            if idx.size:
                self.groups.append(MaterialGroup(f"{name}:{k}", model, params, idx, k,
                                                 first[model.history_names]))
        pts.hist_names = names
        self.offsets, self.slots = node_element_list(elements.conn, nodes.n)
        self._element_geometry()  # vol at x
        elements.vol0 = elements.vol
        bad = np.flatnonzero(elements.vol <= 0.0)
        if bad.size:
            raise ValueError(f"part {name!r}: elements {bad[:10].tolist()} have zero or "
                             "negative volume (inverted node order or collapsed nodes)")
        for g in self.groups:
            rho0 = g.model.density(g.params)
            pts.rho0[g.idx] = rho0
            pts.rho[g.idx] = rho0
            pts.c[g.idx] = g.model.wave_speed(g.params, rho0)
            h0 = g.model.initial_history(g.params)
            if len(h0):
                pts.hist[np.ix_(g.idx, g.column + np.arange(len(h0)))] = h0
        # element mass: the points' densities times their share of the volume
        rho_el = pts.rho0.reshape(ne, self.ngp).mean(axis=1)
        elements.m = rho_el * elements.vol0
        # the point's share of its element's mass [kg] (energies; zero once eroded)
        pts.add("m", (), kind=STATE)
        pts.m = np.repeat(elements.m / self.ngp, self.ngp)
        pts.size = np.repeat(elements.vol0 ** (1.0 / self.dim), self.ngp)
        share = lambda w: np.bincount(elements.conn.ravel(),  # noqa: E731
                                      weights=np.repeat(w / nen, nen), minlength=nodes.n)
        nodes.m = share(elements.m)
        # what walls need of an item (as particles have): volume, density, bulk
        # modulus (node_contact_items)
        self.p = nodes
        for name_ in ("vol0", "rho0", "bulk_modulus"):
            nodes.add(name_, ())
        k_el = np.zeros(ne)
        for g in self.groups:
            k_el[pts.elem[g.idx]] = g.model.bulk_modulus(g.params)
        nodes.vol0, nodes.rho0, nodes.bulk_modulus = node_contact_items(
            elements.conn, elements.vol0, elements.m, k_el, nodes.n, self.dim)
        self._geometry(0.0)  # densities from the masses
        self._element_geometry()  # element steps with the wave speeds

    # ------------------------------------------------------------ kernels
    def _geometry(self, dt: float) -> None:
        """Velocity gradient (mid-step geometry) and the geometry at the current x."""
        q, el, p = self.nodes, self.el, self.pts
        if self.reduced:
            reduced_strain_rate(q.x, q.v, el.conn, el.active, el.m, dt, self.dim, self.tab,
                                self.dN, el.xl, el.g, p.Bg, p.wg, p.wm, p.L, p.rho, el.vol)
        elif self.lanes is not None:
            hex_strain_rate(q.x, q.v, el.conn, el.active, el.m, dt, p.L, p.rho, self.lanes)
        else:
            uniform_strain_rate(q.x, q.v, el.conn, el.active, el.m, dt, self.dim, self.tab,
                                p.L, p.rho, self.work)

    def _element_geometry(self) -> None:
        """Volumes and element steps at the current positions (no forces)."""
        q, el, p, s = self.nodes, self.el, self.pts, self.s
        element_volumes(q.x, el.conn, el.active, self.dim, self.tab, p.c, p.L, p.rho, self.ngp,
                        s.q1, s.q2, self.gam, self.hg_form, s.hourglass_coefficient, el.m,
                        el.vol, el.dt_el, self.work)

    def _forces(self, dt: float) -> None:
        """Element nodal forces (and element steps) gathered into the nodes'
        accelerations; one-point elements compute their end-of-step geometry here."""
        q, el, p, s = self.nodes, self.el, self.pts, self.s
        if self.reduced:
            reduced_forces(el.conn, el.active, p.sig, p.L, p.rho, p.c, p.e, p.e_av, el.g,
                           el.vol, p.Bg, p.wg, s.q1, s.q2, dt, self.dim, el.dt_el, el.fe)
        elif self.lanes is not None:
            hex_forces(q.x, q.v, el.conn, el.active, p.sig, p.L, p.rho, p.c, p.e, p.e_av,
                       self.hg_form, s.hourglass_coefficient, el.hg, el.e_hg, s.q1, s.q2, dt,
                       el.vol, el.dt_el, el.fe, self.lanes, el.m)
        else:
            uniform_forces(q.x, q.v, el.conn, el.active, p.sig, p.L, p.rho, p.c, p.e,
                           p.e_av, self.dim, self.tab, self.gam, self.hg_form,
                           s.hourglass_coefficient, el.hg, el.e_hg, s.q1, s.q2, dt, el.vol,
                           el.dt_el, el.fe, self.work, el.m)
        gather_loads(el.fe, 0, self.offsets, self.slots, q.m, q.a)

    # ----------------------------------------------------------- protocol
    def stable_dt(self) -> tuple[float, int]:
        """Element step and the controlling element (:func:`.solid.min_time_step` of
        the element steps of the last force pass)."""
        return min_time_step(self.el.dt_el, self.el.dt_mass, self.s.cfl, self._dt_t, self._dt_k)

    def scale_mass(self, target: float, mask=None) -> dict[str, np.ndarray]:
        r"""Selective mass scaling (:mod:`sphdyn.mass_scaling`): each active element
        whose step :math:`C\,\Delta t_e` (of the last force pass) is below
        ``target`` gets the step factor :math:`g_e = \Delta t^* / (C\Delta t_e)`
        (``el.dt_mass``) and the mass :math:`(g_e^2 - 1)\, m_e`, shared by its nodes
        as its own mass is (``1/nen`` each): the element's frequencies fall by
        :math:`g_e`, and so its step rises to the target (each node's mass is at
        least every element's scaled share, so the element bound holds). Returns
        the added mass per node [kg] (N,), by table name. ``mask``
        is not used: a mesh is scaled whole."""
        el = self.el
        dt = self.s.cfl * el.dt_el
        # (a step within 1e-9 of the target counts as at it)
        g = np.where((el.active == 1) & (dt < (1.0 - 1e-9) * target), target / dt, 1.0)
        el.dt_mass = g
        added = np.zeros(self.nodes.n)
        np.add.at(added, el.conn.ravel(), np.repeat((g * g - 1.0) * el.m / el.nen, el.nen))
        return {"kin": added}

    @property
    def items_label(self) -> str:
        """What its items are called in a diagnosis (:mod:`sphdyn.watchers.monitors`)."""
        return f"node(s) of mesh '{self.name}'"

    def describe_limit(self, k: int) -> str:
        """What element ``k`` of :meth:`stable_dt` is, for a diagnosis."""
        el = self.el
        centre = self.nodes.x[el.conn[k]].mean(axis=0)
        inverted = ""
        if self.reduced:
            w = self.pts.wg[k * self.ngp:(k + 1) * self.ngp]
            if np.any(w <= 0.0):
                inverted = (f", {int(np.sum(w <= 0.0))} of its {self.ngp} integration "
                            "points inverted (det J <= 0)")
        return (f"element {k} of mesh '{self.name}' at ({', '.join(f'{c:.4g}' for c in centre)})"
                f", volume {el.vol[k] / el.vol0[k]:.3g} of its initial{inverted}"
                f"{self._hourglass_share(k)}")

    def _hourglass_share(self, k: int) -> str:
        """How much the hourglass control's terms shortened element ``k``'s step
        (:func:`.solid.element_step`), and its shape vectors' Gram bound
        against an undistorted element's; empty without hourglass control."""
        el, q, p, s = self.el, self.nodes, self.pts, self.s
        if self.reduced or s.hourglass_coefficient <= 0.0 or not el.active[k]:
            return ""
        xl, g = np.empty((el.nen, 3)), np.empty((el.nen, 3))
        local_coordinates(q.x, q.x, 0.0, el.conn, k, xl)
        V = volume_gradient(xl, self.dim, self.tab, g)
        if V <= 0.0:
            return ""
        dkk = float(np.trace(p.L[k]))
        plain = element_step(char_length(g, V), p.c[k], dkk, s.q1, s.q2, 0.0, 0.0, 0.0)
        lam = hourglass_bound(xl, g, V, self.gam)
        overlap = hourglass_overlap(xl, g, V, self.dim)
        return (f"; its step {el.dt_el[k] / plain:.3g} of what it would be without the "
                f"hourglass control's terms (shape vectors' Gram bound {lam:.3g}, "
                f"{el.nen} undistorted; subspace overlap {overlap:.3g}, 0 undistorted: "
                "docs/theory.md, \"The element step with the hourglass control\")")

    def hotspot(self) -> str:
        """The element of the largest specific internal energy (the energy
        guard's diagnosis, :func:`sphdyn.watchers.guards.energy_diagnosis`) and the
        fastest node."""
        from ...watchers.guards import _fmt, fastest

        el, p = self.el, self.pts
        work = (p.m * p.e).reshape(el.n, self.ngp).sum(axis=1) + el.e_hg
        spec = np.divide(work, el.m, out=np.zeros(el.n), where=(el.m > 0) & (el.active != 0))
        k = int(np.argmax(spec))
        centre = self.nodes.x[el.conn[k]].mean(axis=0)
        hist = "".join(f", {name} {self.element_mean(p.hist[:, j])[k]:.3g}"
                       for j, name in enumerate(p.hist_names) if name == "plastic_strain")
        return (f"element {k} at {_fmt(centre)} has the largest specific internal energy, "
                f"{spec[k]:.4g} J/kg (volume {el.vol[k] / el.vol0[k]:.3g} of its "
                f"initial{hist}); {fastest(self.nodes, 'node')}")

    def start(self, dt: float) -> None:
        """Accelerations of the initial state (no material update)."""
        self._geometry(0.0)
        self._forces(0.0)

    def drift(self, dt: float) -> None:
        drift(self.nodes.x, self.nodes.v, dt)

    def update_geometry(self, t: float, dt: float) -> None:
        return None  # the element geometry needs dt and is computed with the forces

    def internal_forces(self, t: float, dt: float) -> None:
        p = self.pts
        self._geometry(dt)
        if self.reduced:
            p.e_old[:] = p.e
        for g in self.groups:
            g.model.update(g.idx, p.L, dt, p.rho, p.sig, p.e, p.c, p.damage,
                           g.history(p.hist), g.params, p.size)
        if self.reduced:  # each point's work over its own volume
            weigh_point_work(p.e, p.e_old, p.rho, p.wm, p.m)
        self._forces(dt)

    def energies(self) -> tuple[float, float]:
        """Internal energy (material work, bulk viscosity, hourglass) and its
        bulk-viscosity part [J] (J/m in 2D): the points' masses (``pts.m``,
        their element's shared evenly) times their specific energies, summed
        in index order (the same bits with any BLAS or thread count)."""
        p = self.pts
        u, u_av = internal_energies(p.m, p.e, p.e_av)
        return u + self.hourglass_energy(), u_av

    def hourglass_energy(self) -> float:
        """Work done against the hourglass forces [J] (summed in index order)."""
        return ordered_sum(self.el.e_hg)

    def columns(self) -> dict[str, float]:
        """``<name>_E_hourglass``: the hourglass work [J]."""
        return {f"{self.name}_E_hourglass": self.hourglass_energy()}

    # ------------------------------------------------------------ erosion
    def element_points(self, elements: np.ndarray) -> np.ndarray:
        """Point indices (k, ngp) of ``elements`` (k,)."""
        return elements[:, None] * self.ngp + np.arange(self.ngp)[None, :]

    def element_books(self, elements: np.ndarray,
                      dt_half: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""What ``elements`` (k,) carry: masses (k,) [kg]; the kinetic energy of
        their node shares (k,), :math:`\sum_I \tfrac12 (g_e^2 m_e/n_{en})
        |\mathbf v_I + \Delta t_{1/2}\mathbf a_I|^2` [J] (``dt_half``: the
        coming half kick, so at the time the stepper books its kinetic
        energy; :math:`g_e` the mass-scaling factor ``el.dt_mass``, 1 without);
        their internal energy (k,) [J], the points' work ``m e`` plus
        the hourglass work."""
        el, q, p = self.el, self.nodes, self.pts
        m = el.m[elements].copy()
        conn = el.conn[elements]
        ve = q.v[conn] + dt_half * q.a[conn]  # (k, nen, 3)
        # the inertia of the node shares: with a mass scaling's, g_e^2 m_e
        inertia = m * el.dt_mass[elements] ** 2
        kinetic = 0.5 * (inertia / el.nen) * np.sum(ve * ve, axis=(1, 2))
        pts = self.element_points(elements)
        internal = np.sum(p.m[pts] * p.e[pts], axis=1) + el.e_hg[elements]
        return m, kinetic, internal

    def withdraw_forces(self, elements: np.ndarray, dt_half: float) -> np.ndarray:
        r"""Take the nodal loads of ``elements`` (k,) of this step out of their
        nodes' accelerations, :math:`\mathbf a_n \leftarrow \mathbf a_n -
        \sum_{(e, I) \ni n} \mathbf f_{eI} / m_n` (``el.fe`` (E, nen, 3) [N],
        the masses before erosion [kg]); returns each element's work of those
        loads over the coming half kick ``dt_half`` [s] at the nodes'
        mid-step velocities ``v`` [m/s],

        .. math:: W_e = \Delta t_{1/2} \sum_I \mathbf f_{eI}\cdot\mathbf v_I
                  \quad [\mathrm J],

        (nodes of mass > 0), which goes with the element's internal energy
        (:class:`~sphdyn.events.ElementErosion`).

        For an element that fails degenerate (crushed, inverted, its step
        collapsed), which then gives no force in the step it fails in
        (LS-DYNA's practice): its last force is the artefact it fails for
        (at 800 m/s in the penetration deck, 1e12 m/s^2 on its nodes and
        44 kJ of kinetic energy from nothing). Each element's loads sum to
        zero (stress divergence, hourglass and bulk viscosity alike), so the
        momentum rate of the nodes is unchanged to round-off.

        The books. The element's last internal-energy increment (trapezoidal,
        :func:`~sphdyn.materials.base.energy_increment`) holds the work of its
        end-of-step stress over half the step, :math:`\tfrac12\Delta t\,
        \sigma^{n+1}:\mathbf D\,V = -\Delta t_{1/2}\sum_I \mathbf f_{eI}
        \cdot\mathbf v_I`, whose counterpart, the same loads' work in the
        stepper's kinetic-energy book at the coming half kick, the withdrawal
        takes out: :math:`W_e` returned to the internal energy cancels that
        half, as if the stress had done no work after the middle of the step;
        the books are as exact as the integrator's at any step. The exact
        change of that kinetic-energy book, :math:`\tfrac12 m_n(|\mathbf v_n
        + \Delta t_{1/2}\mathbf a_n|^2 - |\mathbf v_n + \Delta t_{1/2}
        \mathbf a'_n|^2)`, also holds the leapfrog's transient
        :math:`\tfrac12 m_n \Delta t_{1/2}^2 (|\mathbf a_n|^2 - |\mathbf
        a'_n|^2)`, second order in the step and present only while the load
        acts; booked as internal energy it became permanent, and for a
        degenerate element's load it is no round-off: 0.8 kJ from one element
        at 3e11 m/s^2 (the 1000 m/s penetration, docs/examples.md). Call
        before :meth:`element_books` and :meth:`erode`.
        """
        el, q = self.el, self.nodes
        elements = np.asarray(elements, dtype=np.int64)
        conn = el.conn[elements]  # (k, nen)
        m = q.inertia()[conn]  # (with a mass scaling's: the accelerations are its)
        inv = np.divide(1.0, m, out=np.zeros_like(m), where=m > 0.0)
        fe = el.fe[elements]  # (k, nen, 3)
        work = dt_half * np.sum(np.sum(fe * q.v[conn], axis=2) * (m > 0.0), axis=1)
        np.subtract.at(q.a, conn.ravel(), (fe * inv[:, :, None]).reshape(-1, 3))
        return work

    def erode(self, elements: np.ndarray) -> None:
        """Take ``elements`` (k,) out of the part (read :meth:`element_books` first).

        Each element's mass leaves its nodes (the lumped share ``m_e / nen``
        each, and a mass scaling's :math:`(g_e^2 - 1) m_e / n_{en}`; their
        accelerations of this step are kept); nodes left with no
        active element get zero mass, zero velocity and ``BC_FIXED``. The
        element's internal energy leaves the part's books: the points' masses
        and the hourglass work are zeroed, their rates too (the material update
        then leaves their stress alone).
        """
        el, q, p = self.el, self.nodes, self.pts
        elements = np.asarray(elements, dtype=np.int64)
        pts = self.element_points(elements)
        nen = el.nen
        el.active[elements] = 0
        el.dt_el[elements] = np.inf
        el.e_hg[elements] = 0.0
        p.m[pts] = 0.0
        p.L[pts] = 0.0
        np.subtract.at(q.m, el.conn[elements].ravel(), np.repeat(el.m[elements] / nen, nen))
        scaled = "m_added" in q.names()  # and the mass a mass scaling gave it
        if scaled:
            extra = (el.dt_mass[elements] ** 2 - 1.0) * el.m[elements] / nen
            np.subtract.at(q.m_added, el.conn[elements].ravel(), np.repeat(extra, nen))
        orphan = np.bincount(el.conn[el.active == 1].ravel(), minlength=q.n) == 0
        q.m[orphan] = 0.0  # exactly: the subtraction leaves round-off
        if scaled:
            q.m_added[orphan] = 0.0
        q.v[orphan] = 0.0
        q.a[orphan] = 0.0
        q.a_ext[orphan] = 0.0
        q.bc[orphan] = BC_FIXED

    # ------------------------------------------------------------- fields
    def element_stress(self) -> np.ndarray:
        """Cauchy stress (E, 3, 3) [Pa]: the mean of the element's points."""
        return self.pts.sig.reshape(self.el.n, self.ngp, 3, 3).mean(axis=1)

    def element_mean(self, values: np.ndarray) -> np.ndarray:
        """Element mean (E, ...) of a per-point array (P, ...)."""
        return values.reshape((self.el.n, self.ngp) + values.shape[1:]).mean(axis=1)

    def fields(self) -> dict:
        """Cell fields (per element) the part evaluates on demand."""
        out = {"stress": self.element_stress,
               "von_mises": lambda: von_mises(self.element_stress()),
               "damage": lambda: self.element_mean(self.pts.damage),
               "density": lambda: self.element_mean(self.pts.rho),
               "hourglass_energy": lambda: self.el.e_hg.copy(),
               "volume": lambda: self.el.vol.copy()}
        for k, name in enumerate(self.pts.hist_names):
            out[name] = (lambda k=k: self.element_mean(self.pts.hist[:, k]))
        return out

    def frame(self, fields=None):
        """The part's picture in an output frame, with the cell ``fields``
        named (:func:`.output.mesh_frame`)."""
        return mesh_frame(self, self.el, self.element_kind, fields)

    def summary(self) -> dict:
        """The part's entry in the run's summary (:func:`.output.mesh_summary`)."""
        return mesh_summary(self, self.el)

    # --------------------------------------------------------- checkpoint
    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        arrays = {f"el.{k}": v for k, v in self.el.arrays().items()}
        arrays.update({f"pt.{k}": v for k, v in self.pts.arrays().items()})
        return {}, arrays

    def restore(self, scalars: dict, arrays: dict) -> None:
        """Continue from a checkpoint (bitwise identical continuation)."""
        for k, v in arrays.items():
            store, name = (self.el, k[3:]) if k.startswith("el.") else (self.pts, k[3:])
            setattr(store, name, v)
        self._element_geometry()  # volumes and element steps of the restored state


def node_contact_items(conn: np.ndarray, vol0: np.ndarray, m: np.ndarray, k: np.ndarray,
                       n: int, dim: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""What a wall sees of each node: the particle of the node's spacing.

    A wall (:mod:`sphdyn.interactions.wall_contact`) takes an item's size
    :math:`V^{1/d}` for its contact thickness :math:`f_t V^{1/d}` and its bulk
    spring :math:`a = \alpha K\delta/(\rho_0 V^{2/d})`. A node's size is
    the mean size of its elements, :math:`h_I = \frac1{n_I}\sum_{e\ni I}
    V_e^{1/d}`, so ``vol0`` is :math:`h_I^d`; ``rho0`` and ``bulk_modulus``
    are the density :math:`\sum m_e / \sum V_e` and the volume-weighted
    bulk modulus of its elements. The size is not the node's share of its
    elements' volume, :math:`(\sum_e V_e/n_{en})^{1/d}`: that is smaller on
    an edge (a quarter) and a corner (an eighth) than on a face (a half), so
    a face of equal elements met the wall in a dent at its edges, and the
    nodes on a symmetry plane met it later than the same nodes of the whole
    model (issue 57; a quarter model with rollers is now the quarter of the
    whole, pinned by a test). Both laws then act alike on every node of a
    uniform face: the mass spring's acceleration :math:`\alpha\delta/\Delta
    t^2` does not depend on the node, the bulk spring's on its size and
    density only, so the force is proportional to the node's mass.

    ``conn`` (E, nen), element volumes ``vol0`` (E,) [m^dim], masses ``m``
    (E,) [kg], bulk moduli ``k`` (E,) [Pa]; ``n`` nodes. Returns ``vol0``,
    ``rho0``, ``bulk_modulus`` (n,) [m^dim, kg/m^3, Pa]; a node of no element
    gets zeros.
    """
    nen = conn.shape[1]
    flat = conn.ravel()
    count = np.bincount(flat, minlength=n).astype(float)
    size = np.bincount(flat, weights=np.repeat(vol0 ** (1.0 / dim), nen), minlength=n)
    vol = np.bincount(flat, weights=np.repeat(vol0, nen), minlength=n)
    used = count > 0
    h = np.divide(size, count, out=np.zeros(n), where=used)
    rho = np.divide(np.bincount(flat, weights=np.repeat(m, nen), minlength=n), vol,
                    out=np.zeros(n), where=used)
    kb = np.divide(np.bincount(flat, weights=np.repeat(k * vol0, nen), minlength=n), vol,
                   out=np.zeros(n), where=used)
    return h ** dim, rho, kb


def solid_part(name: str, points: np.ndarray, cells: np.ndarray, dim: int, materials,
               mat: np.ndarray | None = None,
               settings: SolidSettings = SolidSettings()) -> SolidPart:
    """A :class:`SolidPart` from node coordinates (N, 3) [m] and connectivity (E, nen).

    ``materials``: a ``(model, params)`` pair for every element, or a dict
    material index -> pair with ``mat`` (E,) the elements' indices.
    """
    nodes = Nodes(points.shape[0], dim)
    nodes.x = points
    nodes.x0 = points
    el = Elements(cells.shape[0], cells.shape[1])
    el.conn = cells
    if not isinstance(materials, dict):
        materials = {0: materials}
    if mat is not None:
        el.mat = mat
    return SolidPart(name, nodes, el, materials, settings)
