r"""SPH-FEM coupling by constraint: interface particles move with the element faces.

The thesis's second coupling (chapter 4, "Coupling SPH and FEM"): "one or
more degrees of freedom are tied ... velocities and accelerations of FEM
nodes and SPH particles are coupled". Every particle :math:`s` within
``tie_factor`` sizes of a master face at the start
(:func:`~.penalty_geometry.face_anchors`) becomes a slave of that face at its
parametric point :math:`(\xi, \eta)` with its normal offset :math:`g`:

.. math::
    \mathbf x_s = \sum_a N_a(\xi,\eta)\,\mathbf x_a + g\,\mathbf n,

so it keeps its place against the face when the face translates, rotates or
stretches (the offset turns with the normal; LS-DYNA's constraint-based tied
contacts move the slave onto the face instead, which would squeeze the first
particle layer against the second). Its velocity is linear in the face
nodes' velocities,

.. math::
    \mathbf v_s = \sum_a \mathsf B_a \mathbf v_a, \qquad
    \mathsf B_a = N_a \mathsf I + g\,\frac{\partial\dot{\mathbf n}}{\partial\mathbf v_a},

with, in 3D, :math:`\mathbf c = \mathbf x_{,\xi}\times\mathbf x_{,\eta}`,
:math:`\mathbf n = \mathbf c/|\mathbf c|` and :math:`\dot{\mathbf n} =
(\mathsf I - \mathbf n\mathbf n^T)\,\dot{\mathbf c}/|\mathbf c|`,
:math:`\dot{\mathbf c} = \sum_a (N_{a,\eta}[\mathbf x_{,\xi}]_\times
- N_{a,\xi}[\mathbf x_{,\eta}]_\times)\mathbf v_a`; in 2D :math:`\mathbf n =
\mathsf R\mathbf t/|\mathbf t|`, :math:`\mathbf t = \mathbf x_1 - \mathbf x_0`,
:math:`\mathsf R = ((0, 1), (-1, 0))`, :math:`\dot{\mathbf n} = (\mathsf I -
\mathbf n\mathbf n^T)\mathsf R\,\dot{\mathbf t}/|\mathbf t|`.

The slave's degrees of freedom are the nodes': its mass goes to the face
nodes at the start, :math:`m_a \mathrel{+}= N_a m_s` (lumped), and its force
(what the SPH passes and the other interactions give it,
:math:`\mathbf F_s = m_s(\mathbf a_s + \mathbf a^{ext}_s)`) goes to them by
virtual work, :math:`\mathbf F_a = \mathsf B_a^T\mathbf F_s` (the SPH
part of it as the nodes' internal force, the interactions' part as theirs:
the energy balance books each where it belongs). Because
:math:`\sum_a N_a = 1` and :math:`\sum_a N_{a,\xi} = \sum_a N_{a,\eta} = 0`,
:math:`\sum_a \mathsf B_a = \mathsf I`: linear momentum is conserved exactly,
and :math:`\sum_a \mathbf F_a\cdot\mathbf v_a = \mathbf F_s\cdot\mathbf v_s`:
the transfer does no work of its own. The kick skips slaves (``BC_SLAVE``):
their kinetic energy is the nodes' (counted once). Each step, after the
kick, :meth:`TiedCoupling.constrain` puts the slaves at their anchors and
gives them :math:`\sum_a \mathsf B_a \mathbf v_a`.

The model and its tests: docs/theory.md, "SPH-FEM coupling by constraint".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..state import BC_FREE, BC_SLAVE
from .base import InteractionBase
from .penalty_geometry import exterior_faces, face_anchors, face_shapes

#: parametric corners of a quadrilateral face (module penalty_geometry's order)
_XI_A = np.array([-1.0, 1.0, 1.0, -1.0])
_ETA_A = np.array([-1.0, -1.0, 1.0, 1.0])


@njit(cache=True, error_model="numpy")
def tie_map(xn, face, xi, eta, g, B):
    r"""Anchor point and velocity map of one slave (module docstring).

    Parameters
    ----------
    xn : (M, 3) node positions [m]; face : (nf,) node ids (nf = 4 in 3D, 2 in 2D).
    xi, eta : parametric point; g : normal offset [m].
    B : (4, 3, 3) out, :math:`\mathsf B_a` (rows past nf zero).

    Returns
    -------
    The anchor :math:`\sum_a N_a\mathbf x_a + g\mathbf n` as ``x, y, z`` [m].
    """
    B[:] = 0.0
    nf = face.shape[0]
    N = face_shapes(xi, eta, nf)
    P = np.empty((3, 3))
    if nf == 2:
        a0, a1 = face[0], face[1]
        t0 = xn[a1, 0] - xn[a0, 0]
        t1 = xn[a1, 1] - xn[a0, 1]
        tl = np.sqrt(t0 * t0 + t1 * t1)
        n0, n1 = t1 / tl, -t0 / tl
        # (I - n n^T) R / |t| in the plane, R = ((0, 1), (-1, 0))
        p00, p01, p11 = 1.0 - n0 * n0, -n0 * n1, 1.0 - n1 * n1
        m00, m01 = -p01 / tl, p00 / tl
        m10, m11 = -p11 / tl, p01 / tl
        for a in range(2):
            sgn = -1.0 if a == 0 else 1.0
            B[a, 0, 0] = N[a] + g * sgn * m00
            B[a, 0, 1] = g * sgn * m01
            B[a, 1, 0] = g * sgn * m10
            B[a, 1, 1] = N[a] + g * sgn * m11
            B[a, 2, 2] = N[a]
        return (N[0] * xn[a0, 0] + N[1] * xn[a1, 0] + g * n0,
                N[0] * xn[a0, 1] + N[1] * xn[a1, 1] + g * n1, 0.0)
    e1 = np.zeros(3)
    e2 = np.zeros(3)
    x = np.zeros(3)
    for a in range(4):
        dxi = 0.25 * _XI_A[a] * (1.0 + eta * _ETA_A[a])
        deta = 0.25 * _ETA_A[a] * (1.0 + xi * _XI_A[a])
        for k in range(3):
            e1[k] += dxi * xn[face[a], k]
            e2[k] += deta * xn[face[a], k]
            x[k] += N[a] * xn[face[a], k]
    c0 = e1[1] * e2[2] - e1[2] * e2[1]
    c1 = e1[2] * e2[0] - e1[0] * e2[2]
    c2 = e1[0] * e2[1] - e1[1] * e2[0]
    cl = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    n = np.array([c0 / cl, c1 / cl, c2 / cl])
    for i in range(3):
        for j in range(3):
            P[i, j] = ((1.0 if i == j else 0.0) - n[i] * n[j]) / cl
    for a in range(4):
        dxi = 0.25 * _XI_A[a] * (1.0 + eta * _ETA_A[a])
        deta = 0.25 * _ETA_A[a] * (1.0 + xi * _XI_A[a])
        # C_a = N_a,eta [e1]x - N_a,xi [e2]x : dc/dv_a
        u0 = deta * e1[0] - dxi * e2[0]
        u1 = deta * e1[1] - dxi * e2[1]
        u2 = deta * e1[2] - dxi * e2[2]
        C = np.array([[0.0, -u2, u1], [u2, 0.0, -u0], [-u1, u0, 0.0]])
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += P[i, k] * C[k, j]
                B[a, i, j] = g * s + (N[a] if i == j else 0.0)
    return x[0] + g * n[0], x[1] + g * n[1], x[2] + g * n[2]


@njit(cache=True, error_model="numpy", parallel=True)
def tied_kinematics(slaves, face_of, xi, eta, g, faces, xn, vn, xp, vp, B):
    r"""Slaves at their anchors with :math:`\mathbf v_s = \sum_a \mathsf B_a\mathbf v_a`.

    ``slaves`` (T,) particle rows; ``face_of``, ``xi``, ``eta``, ``g`` (T,)
    their anchors; ``faces`` (F, nf); ``xn``, ``vn`` (M, 3) nodes; ``xp``,
    ``vp`` (N, 3) particles (slave rows written); ``B`` (T, 4, 3, 3) out.
    """
    for k in prange(slaves.shape[0]):
        s = slaves[k]
        face = faces[face_of[k]]
        x0, x1, x2 = tie_map(xn, face, xi[k], eta[k], g[k], B[k])
        xp[s, 0] = x0
        xp[s, 1] = x1
        xp[s, 2] = x2
        for i in range(3):
            acc = 0.0
            for a in range(face.shape[0]):
                for j in range(3):
                    acc += B[k, a, i, j] * vn[face[a], j]
            vp[s, i] = acc


@njit(cache=True, error_model="numpy")
def tied_transfer(slaves, face_of, xi, eta, g, faces, xn, mp, ap, aext_p, mn, a_n, aext_n,
                  B, force):
    r"""Slave forces to the face nodes: :math:`\mathbf F_a = \mathsf B_a^T\mathbf F_s`.

    :math:`\mathbf F_s = m_s(\mathbf a_s + \mathbf a^{ext}_s)` from ``mp``
    (N,), ``ap``, ``aext_p`` (N, 3). The internal part :math:`m_s\mathbf a_s`
    (the SPH passes') is **added** to the nodes' ``a_n`` (M, 3), the part of
    the interactions :math:`m_s\mathbf a^{ext}_s` to their ``aext_n``, each
    divided by the (augmented) mass ``mn`` (M,): the kick books the work of
    the second only, as for any interaction force, so the balance keeps the
    internal forces' work in the internal energy. ``B`` (T, 4, 3, 3) scratch;
    ``force`` (T, 3) out, :math:`\mathbf F_s` [N]. Serial in slave order
    (several slaves share nodes; deterministic).
    """
    for k in range(slaves.shape[0]):
        s = slaves[k]
        face = faces[face_of[k]]
        tie_map(xn, face, xi[k], eta[k], g[k], B[k])
        for i in range(3):
            force[k, i] = mp[s] * (ap[s, i] + aext_p[s, i])
        for a in range(face.shape[0]):
            node = face[a]
            if mn[node] <= 0.0:
                continue
            for j in range(3):
                fi = 0.0
                fe = 0.0
                for i in range(3):
                    fi += B[k, a, i, j] * ap[s, i]
                    fe += B[k, a, i, j] * aext_p[s, i]
                a_n[node, j] += mp[s] * fi / mn[node]
                aext_n[node, j] += mp[s] * fe / mn[node]


class TiedCoupling(InteractionBase):
    """Particles near a solid part's faces tied to them (module docstring).

    Parameters
    ----------
    name : history columns ``F_<name>_x|y|z`` (the resultant force the slaves
        pass to the nodes [N], N/m in 2D) and ``tied_<name>`` (slave count).
    sph_part, solid_part : the parts (slaves: particles; masters: nodes).
    faces : (F, nf) master faces (default: the mesh's exterior faces).
    tie_factor : particles within this many sizes :math:`V^{1/d}` of a face
        are tied (1.0: the first layer of particles made of elements, half a
        size from the face).

    Build it after every other interaction on these particles: it passes on
    the accelerations they were given. The nodes' masses grow by the slaves'
    shares at construction (the ``mass`` output of the nodes includes them).
    """

    def __init__(self, name: str, sph_part, solid_part, faces=None, tie_factor: float = 1.0):
        if not tie_factor > 0.0:
            raise ValueError(f"{name}: tie_factor must be > 0, got {tie_factor}")
        self.name = name
        self.part = sph_part
        self.solid = solid_part
        p, q = sph_part.p, solid_part.nodes
        faces = exterior_faces(solid_part.el.conn) if faces is None else faces
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        (self.slaves, self.face_of, self.xi, self.eta,
         self.g) = face_anchors(p.x, p.vol0 ** (1.0 / p.dim), q.x, self.faces,
                                float(tie_factor), p.dim)
        busy = self.slaves[p.bc[self.slaves] != BC_FREE]
        if busy.size:
            raise ValueError(f"{name}: particles {busy[:5].tolist()} have boundary "
                             "conditions and cannot follow the mesh; keep boundary sets "
                             "away from the tied interface")
        self.B = np.zeros((self.slaves.size, 4, 3, 3))
        self.force = np.zeros((self.slaves.size, 3))
        nf = self.faces.shape[1]
        # each slave's face shape functions: its mass goes to the face's nodes so
        self.shapes = np.array([face_shapes(self.xi[k], self.eta[k], nf)[:nf]
                                for k in range(self.slaves.size)]).reshape(-1, nf)
        for k, s in enumerate(self.slaves):
            for a in range(nf):
                q.m[self.faces[self.face_of[k], a]] += self.shapes[k, a] * p.m[s]
        p.bc[self.slaves] = BC_SLAVE
        self.constrain(0.0, 0.0)

    def slave_map(self):
        """(slave table, slave rows (S,), master table, masters (S, nf), weights
        (S, nf)): each slave's mass is on its face's nodes by the face's shape
        functions (:mod:`sphdyn.mass_scaling` moves its added mass so)."""
        return (self.part.p, self.slaves, self.solid.nodes, self.faces[self.face_of],
                self.shapes)

    def constrain(self, t: float, dt: float) -> None:
        p, q = self.part.p, self.solid.nodes
        tied_kinematics(self.slaves, self.face_of, self.xi, self.eta, self.g, self.faces,
                        q.x, q.v, p.x, p.v, self.B)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        p, q = self.part.p, self.solid.nodes
        # the nodes' share goes to their a_ext, except when the caller asks
        # into a scratch array (the stepper's restore refreshes the columns)
        # (p.a then holds the total acceleration of the checkpoint already)
        live = a_out is p.a_ext
        a_n, aext_n = (q.a, q.a_ext) if live else (np.zeros_like(q.a), np.zeros_like(q.a))
        tied_transfer(self.slaves, self.face_of, self.xi, self.eta, self.g, self.faces,
                      q.x, p.m, p.a, a_out if live else np.zeros_like(a_out), q.m, a_n,
                      aext_n, self.B, self.force)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        return {f"F_{self.name}_x": float(f[0]), f"F_{self.name}_y": float(f[1]),
                f"F_{self.name}_z": float(f[2]), f"tied_{self.name}": float(self.slaves.size)}
