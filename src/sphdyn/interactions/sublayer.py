r"""Sublayer coupling of reinforcement (thesis sec. 6.1): every bar node is also an SPH particle.

SPH bars in tension suffer the tensile instability; the thesis's remedy keeps
the bar as beam or truss elements placed freely inside the SPH concrete and
makes "every FEM node also an SPH particle": the sublayer. The sublayer
particles (of the steel material) meet the concrete particles through their
overlapping supports like any two particles do, so the bond needs no contact
search and no matching of nodes.

Node :math:`n` and its particle :math:`s` are one degree of freedom (as an
SPH element sits on a node in LS-DYNA): the particle is a slave of the node,
:math:`\mathbf x_s = \mathbf x_n`, :math:`\mathbf v_s = \mathbf v_n`
(:meth:`SublayerCoupling.constrain`, after each kick); its mass is in the
node's, :math:`m_n \leftarrow m_n + m_s` (at construction), and its force,
what the SPH passes and the other interactions give it, goes to the node:
:math:`\mathbf a_n \mathrel{+}= m_s\mathbf a_s / m_n` (internal part) and
:math:`\mathbf a^{ext}_n \mathrel{+}= m_s\mathbf a^{ext}_s / m_n` (the
interactions' part, whose work the kick books). Momentum is conserved
exactly and the transfer does no work of its own; the kick skips the slaves
(``BC_SLAVE``), so their kinetic energy is counted once, at the node.

Pairs of two sublayer particles of one bar are out of the SPH passes: the
elements carry the bar's axial and bending mechanics, and such pairs would
add a second, SPH bar in parallel (stiffer, with a stress of several GPa in
the pull-out test) that is prone to the tensile instability in tension (a
free bar sliding in a block blew up with them). After the velocity gradient
their share of it is taken off the particles' ``L`` and their pair factors
are zeroed (the shared pair functions of :mod:`.slaves`), so
a bar particle's strain rate comes from the concrete around it only.

The particles take the density of the concrete around them (and a nominal
volume :math:`m_s/\rho_c`; :func:`sphdyn.build.model.build_model`). A bar
particle's strain rate is sampled from its concrete neighbours with the
weights :math:`m_j/\rho_i` of the energy-consistent velocity gradient
(:mod:`sphdyn.parts.sph.passes`); at the steel's 7850 kg/m^3 those weights
would be the concrete volumes times :math:`\rho_c/\rho_s \approx 0.31`, a
strain rate three times too small. (Before the solver paired its force with
that gradient, volumes :math:`m_j/\rho_j` in ``L`` made the pull-out test
create 14 % of its external work out of nothing at the steel's density.)

The bar's mass :math:`\rho_s A L` is split between the elements and the
particles by the ratio :math:`r` (the particles' share, :math:`0 < r < 1`;
equal, 0.5, by default, as the thesis found best): the elements carry the
density :math:`(1 - r)\rho_s` and each node's particle the mass
:math:`r\,m^{lumped}_n` of the full density (:func:`sublayer_masses`).

With ``stiffness = "axial"`` the particles' stress acts along the bar only
(:mod:`sphdyn.materials.uniaxial`); the coupling writes each particle's bar
direction into its history before each material update
(:func:`bar_directions`).

The model and its tests: docs/theory.md, "Sublayer coupling of rebar".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..materials.uniaxial import H_DIRECTION, UNIAXIAL
from ..parts.sph.gradient import finish_row
from ..state import BC_FREE, BC_SLAVE
from .base import InteractionBase
from .slaves import follow_masters, pass_on, set_pair_gradient, set_pairs_off


def sublayer_masses(x, conn, area, density, ratio):
    r"""Masses of a bar's sublayer particles (N,) [kg]: :math:`r` times the nodes'
    lumped masses of the full bar, :math:`m_n = \sum_{e \ni n} \rho A L_e / 2`.

    ``x`` (N, 3) nodes [m], ``conn`` (E, 2), ``area`` [m^2], ``density``
    [kg/m^3] (the steel's), ``ratio`` in (0, 1).
    """
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"the particles' mass ratio must be in (0, 1), got {ratio}: "
                         "neither the nodes nor the particles may be massless")
    L = np.linalg.norm(x[conn[:, 1]] - x[conn[:, 0]], axis=1)
    m = np.zeros(x.shape[0])
    np.add.at(m, conn[:, 0], 0.5 * density * area * L)
    np.add.at(m, conn[:, 1], 0.5 * density * area * L)
    return ratio * m


@njit(cache=True, error_model="numpy", parallel=True)
def bar_directions(x, conn, offsets, slots, nodes, rows, hist, col):
    r"""Unit direction of the bar at each of its nodes, into ``hist[rows[k],
    col:col+3]``: :math:`\mathbf t_n \propto \sum_{e \ni n} \pm\mathbf u_e`, the
    unit vectors :math:`\mathbf u_e` of the node's elements, each turned to
    point as the first one (a bar's elements need no common orientation; the
    stress :math:`s\,\mathbf t\otimes\mathbf t` does not depend on the sign).
    On a straight bar it is the bar's axis; at a bend, the mean tangent (it
    bisects the two elements' directions).

    ``x`` (N, 3) node positions [m], ``conn`` (E, 2), ``offsets`` (N+1,) and
    ``slots`` the node-to-element list (slot ``2 e + I``), ``nodes`` and
    ``rows`` (n,) each particle's node and row, ``hist`` (P, nh) out.
    """
    for k in prange(nodes.shape[0]):
        n = nodes[k]
        t0 = t1 = t2 = 0.0
        r0 = r1 = r2 = 0.0  # the first element's direction
        for j in range(offsets[n], offsets[n + 1]):
            e = slots[j] // 2
            a, b = conn[e, 0], conn[e, 1]
            u0, u1, u2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
            norm = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
            u0, u1, u2 = u0 / norm, u1 / norm, u2 / norm
            if j == offsets[n]:
                r0, r1, r2 = u0, u1, u2
            elif u0 * r0 + u1 * r1 + u2 * r2 < 0.0:
                u0, u1, u2 = -u0, -u1, -u2
            t0 += u0
            t1 += u1
            t2 += u2
        norm = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        i = rows[k]
        hist[i, col] = t0 / norm
        hist[i, col + 1] = t1 / norm
        hist[i, col + 2] = t2 / norm


@njit(cache=True, error_model="numpy", parallel=True)
def gradient_without_set(rows, member, offsets, idx, fac, x, v, m, rho, dim, L, B, sums):
    r"""Corrected velocity gradient of the set's rows from the pairs with the
    particles outside the set only (the concrete around a bar's particle).

    .. math::
        \mathbf L_i = \sum_{j \notin S} \frac{m_j}{\rho_i} F_{ij}
              (\mathbf v_j - \mathbf v_i) \otimes \mathbf d_{ij}\; Q_i,
        \qquad
        Q_i = \Big[\sum_{j \notin S} \frac{m_j}{\rho_i} F_{ij}
              (\mathbf x_j - \mathbf x_i) \otimes \mathbf d_{ij}\Big]^{-1},
        \qquad \mathbf d_{ij} = \mathbf x_i - \mathbf x_j

    and :math:`B_i = Q_i`: the Randles-Libersky correction of
    :func:`sphdyn.parts.sph.gradient.velocity_gradient` (the same row end,
    :func:`~sphdyn.parts.sph.gradient.finish_row`) with the set's own pairs out
    of both sums, so a bar particle in a linear velocity field has its
    gradient exactly. (Out of the velocity sum only, as without correction,
    the bar's pairs in the moment matrix scaled the strain rate along the bar
    down: by 30 % in the test's block.)

    ``rows`` (S,), ``member`` (N,) bool; ``fac`` (nnz,) the pair factors
    :math:`F_{ij}` [1/m^5 in 3D] before the set's pairs are zeroed; ``x``, ``v``
    (N, 3) [m, m/s]; ``m``, ``rho`` (N,); ``L``, ``B`` (N, 3, 3) rows
    overwritten [1/s, 1]; ``sums`` (S, 2, 3, 3) scratch.
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        G, M = sums[k, 0], sums[k, 1]  # the velocity and moment sums (3, 3)
        G[:] = 0.0
        M[:] = 0.0
        irho = 1.0 / rho[i]
        for q in range(offsets[i], offsets[i + 1]):
            j = idx[q]
            if member[j] or fac[q] == 0.0:
                continue
            f = np.float64(fac[q]) * (m[j] * irho)
            for b in range(3):
                g = f * (x[i, b] - x[j, b])
                for a in range(3):
                    G[a, b] += (v[j, a] - v[i, a]) * g
                    M[a, b] += (x[j, a] - x[i, a]) * g
        finish_row(i, dim, True, G[0, 0], G[0, 1], G[0, 2], G[1, 0], G[1, 1], G[1, 2],
                   G[2, 0], G[2, 1], G[2, 2], M[0, 0], M[0, 1], M[0, 2], M[1, 1], M[1, 2],
                   M[2, 2], L, B)


class SublayerCoupling(InteractionBase):
    """The sublayer particles ``rows`` (n,) of ``sph_part`` tied one to one to the
    nodes ``nodes`` (n,) of ``line_part`` (module docstring).

    History columns: ``F_<name>_x|y|z``, the resultant force the concrete and
    the other interactions exert on the sublayer particles [N] (the bond
    force), and ``sublayer_<name>`` (particle count). Build it after every
    other interaction on the particles: it passes on what they were given.
    """

    def __init__(self, name: str, sph_part, line_part, rows, nodes):
        rows = np.asarray(rows, dtype=np.int64)
        nodes = np.asarray(nodes, dtype=np.int64)
        if rows.shape != nodes.shape or np.unique(nodes).size != nodes.size:
            raise ValueError(f"{name}: one particle per node, each node once")
        p, q = sph_part.p, line_part.kin
        busy = rows[p.bc[rows] != BC_FREE]
        if busy.size:
            raise ValueError(f"{name}: particles {busy[:5].tolist()} have boundary "
                             "conditions; a sublayer particle follows its node")
        if np.any(p.m[rows] <= 0.0) or np.any(q.m[nodes] <= 0.0):
            raise ValueError(f"{name}: sublayer particles and their nodes need mass")
        if np.any(p.tl[rows]):
            raise ValueError(f"{name}: sublayer particles are updated-Lagrangian")
        self.name, self.part, self.line = name, sph_part, line_part
        self.rows, self.nodes = rows, nodes
        q.m[nodes] += p.m[rows]
        p.bc[rows] = BC_SLAVE
        self.force = np.zeros((rows.size, 3))
        self.L_own = np.zeros((rows.size, 3, 3))  # the bar's own pairs' share of L
        self.sums = np.zeros((rows.size, 2, 3, 3))  # scratch of the corrected rows
        # a one-node "element" per particle: the shared slave kernels with N = 1
        self.master = np.ascontiguousarray(nodes[:, None])
        self.one = np.ones((rows.size, 1))
        self.order = np.arange(rows.size, dtype=np.int64)
        self._mask(0, p.n)
        p.on_grow(self._mask)
        sph_part.pair_filters.append(self._pairs_off)
        axial = [g for g in sph_part.groups if g.model is UNIAXIAL
                 and np.isin(rows, g.idx).all()]
        # the uniaxial bar's direction columns in the part's history, or -1
        self.direction = axial[0].column + H_DIRECTION if axial else -1
        self.constrain(0.0, 0.0)

    def _mask(self, n_old: int, n_new: int) -> None:
        self.own = np.zeros(n_new, dtype=np.bool_)
        self.own[self.rows] = True

    def _pairs_off(self) -> None:
        """The SPH part's hook after its pair factors: the share of the bar's own
        pairs in the velocity gradient kept aside, then those pairs out."""
        sph, p = self.part, self.part.p
        if sph.s.correction:  # L and B of the concrete pairs alone
            gradient_without_set(self.rows, self.own, sph.nl.offsets, sph.nl.idx, sph.F, p.x,
                                 p.v, p.m, p.rho, sph.dim, p.L, p.B, self.sums)
        else:
            set_pair_gradient(self.rows, self.own, sph.nl.offsets, sph.nl.idx, sph.F, p.x,
                              p.v, p.m, p.rho, p.B, p.B, False, self.L_own)
            p.L[self.rows] -= self.L_own
        set_pairs_off(self.rows, self.own, sph.nl.offsets, sph.nl.idx, sph.F)
        if self.direction >= 0:  # before the material update reads them
            q = self.line
            bar_directions(q.kin.x, q.elements.conn, q.ptr, q.ent, self.nodes, self.rows,
                           p.hist, self.direction)

    def slave_map(self):
        """(slave table, slave rows (S,), master table, masters (S, 1), weights (S,
        1)): each particle follows its node (:mod:`sphdyn.mass_scaling` moves a
        slave's added mass to its node)."""
        return self.part.p, self.rows, self.line.kin, self.master, self.one

    def constrain(self, t: float, dt: float) -> None:
        p, q = self.part.p, self.line.kin
        follow_masters(self.rows, self.order, self.one, self.master, q.x, q.v, p.x, p.v)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        pass_on(self.part.p, self.line.kin, self.rows, self.order, self.one, self.master,
                a_out, self.force)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        return {f"F_{self.name}_x": float(f[0]), f"F_{self.name}_y": float(f[1]),
                f"F_{self.name}_z": float(f[2]),
                f"sublayer_{self.name}": float(self.rows.size)}
