r"""Items that ride on masters, and pairs of a set of particles among themselves.

Shared by the couplings whose slaves move with other degrees of freedom
(:mod:`.hybrid_coupling`: particles at an element's integration points;
:mod:`.sublayer`: a bar's particles on its nodes; :mod:`.embedded`: a bar's
nodes in solid elements):

* :func:`follow_masters`: a slave's position and velocity, the shape-function
  sums :math:`\sum_a N_a (\mathbf x_a, \mathbf v_a)` of its masters;
* :func:`forces_to_masters`: its force :math:`\mathbf F_s = m_s(\mathbf a_s +
  \mathbf a^{ext}_s)` to the masters, :math:`N_a\mathbf F_s` (momentum exact
  for :math:`\sum_a N_a = 1`);
* :func:`set_pair_gradient`, :func:`set_pairs_off`, :func:`remove_pair_work`:
  the pairs of two particles of one set (hybrid layer, one bar) out of the
  updated-Lagrangian force pass, their share of the velocity gradient kept
  aside (and, where the material keeps it, their stress work off the energy).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, error_model="numpy", parallel=True)
def follow_masters(rows, elem, N, conn, xn, vn, xp, vp):
    r""":math:`\mathbf x_s, \mathbf v_s = \sum_a N_a(\boldsymbol\xi_s)(\mathbf x_a, \mathbf v_a)`.

    ``rows`` (S,) the slaves' rows, ``elem`` (S,) their masters' element (row
    of ``conn``), ``N`` (S, nen) shape functions at their points, ``conn``
    (E, nen) master indices; ``xn``, ``vn`` (M, 3) masters; ``xp``, ``vp``
    (N, 3) (the slaves' rows written).
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
def set_pair_gradient(rows, member, offsets, idx, fac, pos, v, w, rho, B, Finv, tl, Lhh):
    r"""The share of the pairs within a set in each member's velocity gradient.

    Updated-Lagrangian (``tl`` False; the terms of
    :func:`sphdyn.parts.sph.gradient.velocity_gradient` that those pairs gave):

    .. math:: \mathbf L^{ss}_i = \Big[\sum_{j\ \mathrm{in\ the\ set}}
              \frac{m_j}{\rho_i}\,
              F_{ij} (\mathbf v_j - \mathbf v_i) \otimes
              (\mathbf x_i - \mathbf x_j)\Big] B_i^T;

    total-Lagrangian (``tl`` True; the terms of
    :func:`sphdyn.parts.sph.total_lagrangian.deformation_gradient`, with
    :math:`\mathbf L = \dot F F^{-1}`): the same sum with the reference
    positions :math:`\mathbf X`, volumes and factors, times :math:`F_i^{-1}`.
    Since :math:`\sigma : \mathbf L\, V = P : \dot F\, V_0`,
    :func:`remove_pair_work` serves both.

    ``rows`` (S,) the members' rows, ``member`` (N,) bool; ``fac`` (nnz,) the
    pair factors of all pairs (UL: before :func:`set_pairs_off`); ``pos``,
    ``v`` (N, 3) the positions of the sum (current or reference) and
    velocities; ``w`` (N,) the weights of the pass (UL: the masses, divided
    here by ``rho`` (N,) of row i; TL: the reference volumes, ``rho``
    unused); ``B`` and ``Finv``
    (N, 3, 3) (``Finv`` unused in UL); ``Lhh`` (S, 3, 3) out [1/s].
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        for a in range(3):
            for b in range(3):
                Lhh[k, a, b] = 0.0
        scale = 1.0 if tl else 1.0 / rho[i]
        for q in range(offsets[i], offsets[i + 1]):
            j = idx[q]
            if not member[j]:
                continue
            f = np.float64(fac[q]) * (w[j] * scale)
            for a in range(3):
                u = v[j, a] - v[i, a]
                for b in range(3):
                    Lhh[k, a, b] += u * f * (pos[i, b] - pos[j, b])
        for a in range(3):  # times B^T (then F^-1), row by row in place
            r0 = Lhh[k, a, 0]
            r1 = Lhh[k, a, 1]
            r2 = Lhh[k, a, 2]
            for b in range(3):
                Lhh[k, a, b] = r0 * B[i, b, 0] + r1 * B[i, b, 1] + r2 * B[i, b, 2]
            if tl:
                r0 = Lhh[k, a, 0]
                r1 = Lhh[k, a, 1]
                r2 = Lhh[k, a, 2]
                for b in range(3):
                    Lhh[k, a, b] = r0 * Finv[i, 0, b] + r1 * Finv[i, 1, b] + r2 * Finv[i, 2, b]


@njit(cache=True, error_model="numpy")
def remove_pair_work(rows, sig, rho, Lhh, dt, e):
    r""":math:`e_i \mathrel{-}= \Delta t\,\sigma_i : \mathbf L^{ss}_i / \rho_i`: the
    stress work the material update booked for the pairs within the set,
    which carry no force (for the hybrid layer, the element books it).
    ``sig`` (N, 3, 3) [Pa]; ``rho`` (N,); ``Lhh`` (S, 3, 3) [1/s]; ``e`` (N,)
    [J/kg] in place."""
    for k in range(rows.shape[0]):
        i = rows[k]
        w = 0.0
        for a in range(3):
            for b in range(3):
                w += sig[i, a, b] * Lhh[k, a, b]
        e[i] -= dt * w / rho[i]


@njit(cache=True, error_model="numpy", parallel=True)
def set_pairs_off(rows, member, offsets, idx, F):
    """Zero the pair gradient factor ``F`` (nnz,) of every pair within the set
    (both directions: every member's row is visited); ``member`` (N,) bool."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        for q in range(offsets[i], offsets[i + 1]):
            if member[idx[q]]:
                F[q] = 0.0


@njit(cache=True, error_model="numpy")
def forces_to_masters(rows, elem, N, conn, mp, ap, aext_p, mn, a_n, aext_n, force):
    r"""Slaves' forces to their masters, :math:`N_a\mathbf F_s / m_a`:
    the part of the slave's own passes :math:`m_s\mathbf a_s` (SPH pairs, a
    bar's elements) **added** to ``a_n`` (M, 3), the interactions' part
    :math:`m_s\mathbf a^{ext}_s` to ``aext_n`` (as
    :func:`~.tied_coupling.tied_transfer`); ``force`` (S, 3) out,
    :math:`\mathbf F_s` [N]. Serial in slave order (slaves share masters;
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


def pass_on(slaves, masters, rows, elem, N, conn, a_out, force) -> bool:
    """:func:`forces_to_masters` as a coupling's ``forces`` call does it.

    ``slaves``, ``masters``: the kinematics tables (``m``, ``a``, ``a_ext``).
    In a step ``a_out`` is the slaves' ``a_ext``: the masters' ``a`` and
    ``a_ext`` get the shares. Otherwise (the stepper's restore refreshing the
    columns; the slaves' ``a`` then holds their total acceleration already)
    only ``force`` is refreshed. Returns whether it was a step's call.
    """
    live = a_out is slaves.a_ext
    if live:
        forces_to_masters(rows, elem, N, conn, slaves.m, slaves.a, a_out, masters.m,
                          masters.a, masters.a_ext, force)
    else:
        scratch = np.zeros_like(masters.a)
        forces_to_masters(rows, elem, N, conn, slaves.m, slaves.a, np.zeros_like(a_out),
                          masters.m, scratch, scratch, force)
    return live
