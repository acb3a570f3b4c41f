r"""SPH-FEM coupling by a transition layer of hybrid elements.

The thesis's third coupling (chapter 4, "Coupling SPH and FEM"): "hybrid FEM
elements ... contain SPH particles placed inside them, e.g. at locations of
the integration (material) points. The motion of FEM elements and SPH
particles is again coupled, yet the transition between the hybrid elements
and other SPH particles is done with the kernel approximation". The hybrid
elements are the first layer of remaining elements next to the particles
(:func:`sphdyn.geometry.convert.hybrid_points`); each of their integration points
:math:`\boldsymbol\xi_h` carries a particle :math:`h` of the element's
material with the point's volume and mass.

* Motion: :math:`\mathbf x_h = \sum_a N_a(\boldsymbol\xi_h)\mathbf x_a`,
  :math:`\mathbf v_h = \sum_a N_a(\boldsymbol\xi_h)\mathbf v_a` (the point
  moves with its element exactly; :meth:`HybridCoupling.constrain` after the
  kick, which skips these ``BC_SLAVE`` particles: their mass is the
  element's, counted once).
* Stress: the particle's own. It is an SPH particle of the element's
  material whose velocity gradient comes from the kernel like any other's
  (its neighbours: SPH particles on one side, hybrid particles on the
  other, all moving as the continuum does), so the particles next to the
  interface see a consistent stress field. (Giving it the element's stress
  instead, from the element's velocity gradient, was tried: the beam of
  examples/beam_hybrid.toml came out 6.4 % soft at 80 x 4 x 4 and lost 3 %
  of its strain energy at the interface, against 3.7 % and 0.02 % this way.)
* Forces: pairs of two hybrid particles are taken out of the momentum
  equation (their pair gradient factor is set to zero after the velocity
  gradients, which keep them; the element carries its own stiffness; with
  the total-Lagrangian kernel the pairs are fixed, so the scheme's force
  pass drops them once, :meth:`~sphdyn.parts.sph.tl_scheme.TotalLagrangian.forces_off`), pairs
  of a hybrid and an SPH particle stay: the hybrid particle gets the equal
  and opposite pair force, which goes to the element's nodes,
  :math:`\mathbf F_a = N_a(\boldsymbol\xi_h)\,\mathbf F_h`,
  :math:`\mathbf F_h = m_h(\mathbf a_h + \mathbf a^{ext}_h)`. With
  :math:`\sum_a N_a = 1` linear momentum is conserved exactly.
* Energy: the element books the strain energy of its material. A hybrid
  particle's material update books :math:`\sigma_h : \mathbf L_h` with its
  whole velocity gradient, but only its pairs with SPH particles carry
  forces; the share of the hybrid-hybrid pairs,
  :math:`\Delta t\,\sigma_h:\mathbf L^{hh}_h/\rho_h`
  (:func:`~.slaves.set_pair_gradient`), is taken off again after the step, so its
  internal energy is the work of the interface's pair forces on its side
  (the SPH energy equation's share), with its share of the viscous heat.

The model and its tests: docs/theory.md, "SPH-FEM coupling by a hybrid transition layer".
"""

from __future__ import annotations

import numpy as np

from ..geometry.shapes import shape_functions
from ..state import BC_FREE, BC_SLAVE
from .base import InteractionBase
from .slaves import (follow_masters, pass_on, remove_pair_work, set_pair_gradient,
                     set_pairs_off)


class HybridCoupling(InteractionBase):
    """A transition layer of hybrid elements (module docstring).

    Parameters
    ----------
    name : history columns ``F_<name>_x|y|z`` (resultant force the hybrid
        particles pass to the nodes [N], N/m in 2D) and ``hybrid_<name>``.
    sph_part : the SPH part holding the hybrid particles (updated- or
        total-Lagrangian).
    solid_part : the solid part of the hybrid elements.
    rows : (H,) the hybrid particles' rows in the SPH part.
    elem : (H,) their elements in the solid part.
    xi : (H, d) their natural coordinates in the element.

    Build it after every other interaction on these particles.
    """

    def __init__(self, name: str, sph_part, solid_part, rows, elem, xi):
        p, q = sph_part.p, solid_part.nodes
        self.name = name
        self.part = sph_part
        self.solid = solid_part
        self.rows = self.slaves = np.asarray(rows, dtype=np.int64)
        self.elem = np.asarray(elem, dtype=np.int64)
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        d = solid_part.dim
        if xi.shape != (self.rows.size, d) or self.elem.shape != self.rows.shape:
            raise ValueError(f"{name}: rows (H,), elem (H,) and xi (H, {d}) must agree, "
                             f"got {self.rows.shape}, {self.elem.shape}, {xi.shape}")
        tl = p.tl[self.rows]
        if tl.any() and not tl.all():
            raise ValueError(f"{name}: the hybrid particles must all be updated- or all "
                             "total-Lagrangian")
        self.tl = bool(tl.all())
        busy = self.rows[p.bc[self.rows] != BC_FREE]
        if busy.size:
            raise ValueError(f"{name}: particles {busy[:5].tolist()} have boundary "
                             "conditions and cannot follow the mesh")
        self.conn = np.ascontiguousarray(solid_part.el.conn, dtype=np.int64)
        self.N = np.ascontiguousarray(shape_functions(d, xi))
        self.force = np.zeros((self.rows.size, 3))
        self.Lhh = np.zeros((self.rows.size, 3, 3))
        self.dt = 0.0
        self._mask(0, p.n)
        p.on_grow(self._mask)
        p.bc[self.rows] = BC_SLAVE
        self.constrain(0.0, 0.0)
        if self.tl:  # the pairs are fixed: out of the force pass once
            sph_part.tl.forces_off(self.hybrid)
        sph_part.pair_filters.append(self._pairs_off)

    def _mask(self, n_old: int, n_new: int) -> None:
        self.hybrid = np.zeros(n_new, dtype=np.bool_)
        self.hybrid[self.rows] = True

    def _pairs_off(self) -> None:
        """The SPH part's hook after its pair factors: the hybrid pairs' share of
        the velocity gradient kept aside, then the pairs out."""
        sph = self.part
        p = sph.p
        if self.tl:  # the pairs are out of the TL force pass already
            t = sph.tl
            set_pair_gradient(self.rows, self.hybrid, t.offsets, t.idx, t.fac, t.X, p.v,
                              t.vol, p.rho, t.B0, t.Finv, True, self.Lhh)
            return
        set_pair_gradient(self.rows, self.hybrid, sph.nl.offsets, sph.nl.idx, sph.F,
                          p.x, p.v, p.m, p.rho, p.B, p.B, False, self.Lhh)
        set_pairs_off(self.rows, self.hybrid, sph.nl.offsets, sph.nl.idx, sph.F)

    def slave_map(self):
        """(slave table, slave rows (S,), master table, masters (S, nen), weights
        (S, nen)): each hybrid particle follows its element's nodes with the shape
        functions (:mod:`sphdyn.mass_scaling` moves a slave's added mass so)."""
        return self.part.p, self.rows, self.solid.nodes, self.conn[self.elem], self.N

    def constrain(self, t: float, dt: float) -> None:
        p, q = self.part.p, self.solid.nodes
        self.dt = dt  # the step the material update of this step will take
        follow_masters(self.rows, self.elem, self.N, self.conn, q.x, q.v, p.x, p.v)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p = self.part.p
        if pass_on(p, self.solid.nodes, self.rows, self.elem, self.N, self.conn, a_out,
                   self.force):
            remove_pair_work(self.rows, p.sig, p.rho, self.Lhh, self.dt, p.e)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        return {f"F_{self.name}_x": float(f[0]), f"F_{self.name}_y": float(f[1]),
                f"F_{self.name}_z": float(f[2]), f"hybrid_{self.name}": float(self.rows.size)}
