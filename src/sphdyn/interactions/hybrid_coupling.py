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
  and opposite pair force, which goes to the element's nodes, :math:`\mathbf F_a = N_a(\boldsymbol\xi_h)\,\mathbf F_h`,
  :math:`\mathbf F_h = m_h(\mathbf a_h + \mathbf a^{ext}_h)`. With
  :math:`\sum_a N_a = 1` linear momentum is conserved exactly.
* Energy: the element books the strain energy of its material. A hybrid
  particle's material update books :math:`\sigma_h : \mathbf L_h` with its
  whole velocity gradient, but only its pairs with SPH particles carry
  forces; the share of the hybrid-hybrid pairs,
  :math:`\Delta t\,\sigma_h:\mathbf L^{hh}_h/\rho_h`
  (:func:`hybrid_pair_gradient`), is taken off again after the step, so its
  internal energy is the work of the interface's pair forces on its side
  (the SPH energy equation's share), with its share of the viscous heat.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..geometry.shapes import shape_functions
from ..state import BC_FREE, BC_SLAVE
from .base import InteractionBase


@njit(cache=True, error_model="numpy", parallel=True)
def hybrid_kinematics(rows, elem, N, conn, xn, vn, xp, vp):
    r""":math:`\mathbf x_h, \mathbf v_h = \sum_a N_a(\boldsymbol\xi_h)(\mathbf x_a, \mathbf v_a)`.

    ``rows`` (H,) particle rows, ``elem`` (H,) their elements, ``N`` (H, nen)
    shape functions at their points, ``conn`` (E, nen); ``xn``, ``vn`` (M, 3);
    ``xp``, ``vp`` (N, 3) (hybrid rows written).
    """
    for k in prange(rows.shape[0]):
        h = rows[k]
        e = elem[k]
        for i in range(3):
            x = 0.0
            v = 0.0
            for a in range(conn.shape[1]):
                x += N[k, a] * xn[conn[e, a], i]
                v += N[k, a] * vn[conn[e, a], i]
            xp[h, i] = x
            vp[h, i] = v


@njit(cache=True, error_model="numpy", parallel=True)
def hybrid_pair_gradient(rows, hybrid, offsets, idx, fac, pos, v, vol, B, Finv, tl, Lhh):
    r"""The hybrid-hybrid pairs' part of each hybrid particle's velocity gradient.

    Updated-Lagrangian (``tl`` False; the terms of
    :func:`sphdyn.parts.sph.passes.velocity_gradient` that those pairs gave):

    .. math:: \mathbf L^{hh}_h = \Big[\sum_{j\ \mathrm{hybrid}} V_j\,
              F_{hj} (\mathbf v_j - \mathbf v_h) \otimes
              (\mathbf x_h - \mathbf x_j)\Big] B_h^T;

    total-Lagrangian (``tl`` True; the terms of
    :func:`sphdyn.parts.sph.total_lagrangian.deformation_gradient`, with
    :math:`\mathbf L = \dot F F^{-1}`): the same sum with the reference
    positions :math:`\mathbf X`, volumes and factors, times :math:`F_h^{-1}`.
    Since :math:`\sigma : \mathbf L\, V = P : \dot F\, V_0`,
    :func:`remove_pair_work` serves both.

    ``fac`` (nnz,) the pair factors of all pairs (UL: before
    :func:`hybrid_pairs_off`); ``pos``, ``v`` (N, 3) the positions of the
    sum (current or reference) and velocities; ``vol`` (N,) the volumes the
    pass used; ``B`` and ``Finv`` (N, 3, 3) (``Finv`` unused in UL);
    ``Lhh`` (H, 3, 3) out [1/s].
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        raw = np.zeros((3, 3))
        for q in range(offsets[i], offsets[i + 1]):
            j = idx[q]
            if not hybrid[j]:
                continue
            f = np.float64(fac[q]) * vol[j]
            for a in range(3):
                u = v[j, a] - v[i, a]
                for b in range(3):
                    raw[a, b] += u * f * (pos[i, b] - pos[j, b])
        out = np.zeros((3, 3))
        for a in range(3):
            for b in range(3):
                s = 0.0
                for c in range(3):
                    s += raw[a, c] * B[i, b, c]
                out[a, b] = s
        for a in range(3):
            for b in range(3):
                if tl:
                    Lhh[k, a, b] = (out[a, 0] * Finv[i, 0, b] + out[a, 1] * Finv[i, 1, b]
                                    + out[a, 2] * Finv[i, 2, b])
                else:
                    Lhh[k, a, b] = out[a, b]


@njit(cache=True, error_model="numpy")
def remove_pair_work(rows, sig, rho, Lhh, dt, e):
    r""":math:`e_h \mathrel{-}= \Delta t\,\sigma_h : \mathbf L^{hh}_h / \rho_h`: the
    stress work the material update booked for the hybrid-hybrid pairs, which
    carry no force (their element books it). ``sig`` (N, 3, 3) [Pa]; ``rho``
    (N,); ``Lhh`` (H, 3, 3) [1/s]; ``e`` (N,) [J/kg] in place."""
    for k in range(rows.shape[0]):
        i = rows[k]
        w = 0.0
        for a in range(3):
            for b in range(3):
                w += sig[i, a, b] * Lhh[k, a, b]
        e[i] -= dt * w / rho[i]


@njit(cache=True, error_model="numpy", parallel=True)
def hybrid_pairs_off(rows, hybrid, offsets, idx, F):
    """Zero the pair gradient factor ``F`` (nnz,) of every hybrid-hybrid pair
    (both directions: every hybrid row is visited); ``hybrid`` (N,) bool."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        for q in range(offsets[i], offsets[i + 1]):
            if hybrid[idx[q]]:
                F[q] = 0.0


@njit(cache=True, error_model="numpy")
def hybrid_transfer(rows, elem, N, conn, mp, ap, aext_p, mn, a_n, aext_n, force):
    r"""Hybrid particles' forces to their elements' nodes, :math:`N_a\mathbf F_h / m_a`:
    the SPH passes' part :math:`m_h\mathbf a_h` **added** to ``a_n`` (M, 3),
    the interactions' part :math:`m_h\mathbf a^{ext}_h` to ``aext_n`` (as
    :func:`~.tied_coupling.tied_transfer`); ``force`` (H, 3) out,
    :math:`\mathbf F_h` [N]. Serial in particle order (elements share nodes;
    deterministic)."""
    for k in range(rows.shape[0]):
        h = rows[k]
        e = elem[k]
        for i in range(3):
            force[k, i] = mp[h] * (ap[h, i] + aext_p[h, i])
        for a in range(conn.shape[1]):
            node = conn[e, a]
            if mn[node] > 0.0:
                w = N[k, a] * mp[h] / mn[node]
                for i in range(3):
                    a_n[node, i] += w * ap[h, i]
                    aext_n[node, i] += w * aext_p[h, i]


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
            hybrid_pair_gradient(self.rows, self.hybrid, t.offsets, t.idx, t.fac, t.X, p.v,
                                 t.vol, t.B0, t.Finv, True, self.Lhh)
            return
        hybrid_pair_gradient(self.rows, self.hybrid, sph.nl.offsets, sph.nl.idx, sph.F,
                             p.x, p.v, p.vol, p.B, p.B, False, self.Lhh)
        hybrid_pairs_off(self.rows, self.hybrid, sph.nl.offsets, sph.nl.idx, sph.F)

    def constrain(self, t: float, dt: float) -> None:
        p, q = self.part.p, self.solid.nodes
        self.dt = dt  # the step the material update of this step will take
        hybrid_kinematics(self.rows, self.elem, self.N, self.conn, q.x, q.v, p.x, p.v)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p, q = self.part.p, self.solid.nodes
        live = a_out is p.a_ext  # else the stepper's restore (see TiedCoupling.forces)
        a_n, aext_n = (q.a, q.a_ext) if live else (np.zeros_like(q.a), np.zeros_like(q.a))
        hybrid_transfer(self.rows, self.elem, self.N, self.conn, p.m, p.a,
                        a_out if live else np.zeros_like(a_out), q.m, a_n, aext_n,
                        self.force)
        if live:
            remove_pair_work(self.rows, p.sig, p.rho, self.Lhh, self.dt, p.e)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        return {f"F_{self.name}_x": float(f[0]), f"F_{self.name}_y": float(f[1]),
                f"F_{self.name}_z": float(f[2]), f"hybrid_{self.name}": float(self.rows.size)}
