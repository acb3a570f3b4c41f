r"""A non-reflecting (viscous) boundary on faces of a solid mesh: waves leave the model.

A model cut out of a larger body (a target block out of a wide slab, a
culvert's concrete) reflects the waves that reach its cut faces: as tension
from a free face, as compression from a fixed one. The viscous boundary of
Lysmer & Kuhlemeyer (1969, "Finite dynamic model for infinite media", J. Eng.
Mech. Div. ASCE 95(EM4), 859-877; LS-DYNA's BOUNDARY_NON_REFLECTING) puts
on each face the traction of the half-space beyond it,

.. math:: \mathbf t = -\rho c_d\,(\mathbf v\cdot\mathbf n)\,\mathbf n
          - \rho c_s\,\bigl(\mathbf v - (\mathbf v\cdot\mathbf n)\,\mathbf n\bigr),

with the dilatational and shear wave speeds :math:`c_d = \sqrt{(K + 4G/3)/\rho}`,
:math:`c_s = \sqrt{G/\rho}` of the face's element (its material's elastic
constants and reference density). A plane P or S wave meeting the face at
normal incidence leaves without reflection; at oblique incidence a part is
reflected (a spherical pulse in a cube with six such faces keeps 8e-5 of its
energy in motion after three crossings, against 4e-2 with free faces:
tests/test_non_reflecting.py).

**Nodal forces.** Lumped with the face's shape functions: node :math:`a` of
a face takes :math:`\mathbf f_a = -\mathbf C_a \mathbf v_a` with

.. math:: \mathbf C_a = |\mathbf S_a|\,\bigl(\rho c_s\,\mathbf I
          + \rho (c_d - c_s)\,\mathbf n_a \mathbf n_a^T\bigr),\qquad
          \mathbf S_a = \int_\Gamma N_a\,\mathbf n\,dA,\ \
          \mathbf n_a = \mathbf S_a / |\mathbf S_a|

(:func:`~sphdyn.interactions.pressure.face_area_vectors`, on the current
positions; a flat face gives each corner a quarter of its area, a 2D edge
each end half its length per unit thickness). A node on several faces sums
their :math:`\mathbf C_a` (each face takes out its own normal: a corner
absorbs both directions).

**Time centring.** The dashpots act at :math:`t^{n+1}` on the velocity there,
predicted from :math:`\mathbf v^{n+1/2}` and the internal accelerations
:math:`\mathbf a^{n+1}_{int}` (trapezoidal in the dashpot, per node a 3 x 3
solve):

.. math:: \Bigl(\mathbf I + \tfrac{\Delta t}{2m}\mathbf C\Bigr)\,\mathbf v^{n+1}
          = \mathbf v^{n+1/2} + \tfrac{\Delta t}{2}\mathbf a^{n+1}_{int},\qquad
          \mathbf a_{nrb} = -\mathbf C\,\mathbf v^{n+1} / m .

The plain lagged form :math:`-\mathbf C\mathbf v^{n+1/2}/m` would be unstable
above about 0.72 of a boundary element's step (a boundary node's dashpot rate
:math:`C/m = 2 c_d/\ell` in 1D); the centred one is stable to the element's
step and passes a 1D pulse with no reflection at the Courant number 1
(tests/test_non_reflecting.py).

**Energy.** The dashpots' work (negative: energy carried out through the
boundary) is external work (``W_external``), so the energy balance holds;
``<name>_absorbed`` reports the energy taken out so far. A face of an eroded
element takes no part. See docs/theory.md, "Non-reflecting boundary".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .pressure import FaceInteraction, face_area_vectors


@njit(cache=True, error_model="numpy")
def boundary_dashpots(x, faces, local, elements, active, z_d, z_s, S, C):
    r"""Dashpot matrices :math:`\mathbf C_a = \sum_{faces} |\mathbf S_a|(z_s \mathbf I +
    (z_d - z_s)\mathbf n_a\mathbf n_a^T)` [kg/s] of the face nodes (module docstring),
    written to ``C`` (k, 3, 3).

    ``x`` (N, 3) current node positions [m]; ``faces`` (F, 4) or (F, 2) outward
    order; ``local`` (F, nf) each face node's row in ``C``; ``elements`` (F,) and
    ``active`` (E,) int8: a face of an inactive element adds nothing; ``z_d``,
    ``z_s`` (F,) the impedances :math:`\rho c_d`, :math:`\rho c_s` [kg/(m^2 s)]
    of each face's element; ``S`` (nf, 3) scratch. Serial: faces share nodes."""
    for k in range(C.shape[0]):
        for i in range(3):
            for j in range(3):
                C[k, i, j] = 0.0
    nf = faces.shape[1]
    for f in range(faces.shape[0]):
        if active[elements[f]] == 0:
            continue
        face_area_vectors(x, faces, f, S)
        for a in range(nf):
            area = math.sqrt(S[a, 0] * S[a, 0] + S[a, 1] * S[a, 1] + S[a, 2] * S[a, 2])
            if area == 0.0:
                continue
            r = local[f, a]
            d = (z_d[f] - z_s[f]) / area  # |S| (z_d - z_s) n n^T = (z_d - z_s) S S^T / |S|
            for i in range(3):
                C[r, i, i] += z_s[f] * area
                for j in range(3):
                    C[r, i, j] += d * S[a, i] * S[a, j]


@njit(cache=True, error_model="numpy")
def dashpot_accelerations(nodes, m, C, v, a_int, dt, a_own, a_out):
    r"""The dashpots' accelerations at :math:`t^{n+1}` (module docstring):
    :math:`(\mathbf I + \tfrac{\Delta t}{2m}\mathbf C)\mathbf w = \mathbf v +
    \tfrac{\Delta t}{2}\mathbf a_{int}`, ``a_own[k] = -C w / m`` (k, 3) [m/s^2],
    added to ``a_out[nodes[k]]`` (N, 3).

    ``nodes`` (k,) the face nodes, ``m`` (N,) their masses [kg], ``C`` (k, 3, 3)
    [kg/s] (:func:`boundary_dashpots`), ``v`` (N, 3) :math:`\mathbf v^{n+1/2}`,
    ``a_int`` (N, 3) the internal accelerations at :math:`t^{n+1}`, ``dt`` [s].
    The matrix is symmetric positive definite (C is positive semi-definite):
    solved by its adjugate. A node without mass (every element about it
    eroded, so its faces are gone too) gets none: ``a_own[k] = 0``."""
    for k in range(nodes.shape[0]):
        i = nodes[k]
        if not m[i] > 0.0:
            for j in range(3):
                a_own[k, j] = 0.0
            continue
        s = 0.5 * dt / m[i]
        a00 = 1.0 + s * C[k, 0, 0]
        a11 = 1.0 + s * C[k, 1, 1]
        a22 = 1.0 + s * C[k, 2, 2]
        a01 = s * C[k, 0, 1]
        a02 = s * C[k, 0, 2]
        a12 = s * C[k, 1, 2]
        b0 = v[i, 0] + 0.5 * dt * a_int[i, 0]
        b1 = v[i, 1] + 0.5 * dt * a_int[i, 1]
        b2 = v[i, 2] + 0.5 * dt * a_int[i, 2]
        c00 = a11 * a22 - a12 * a12
        c01 = a02 * a12 - a01 * a22
        c02 = a01 * a12 - a02 * a11
        c11 = a00 * a22 - a02 * a02
        c12 = a01 * a02 - a00 * a12
        c22 = a00 * a11 - a01 * a01
        det = a00 * c00 + a01 * c01 + a02 * c02
        w0 = (c00 * b0 + c01 * b1 + c02 * b2) / det
        w1 = (c01 * b0 + c11 * b1 + c12 * b2) / det
        w2 = (c02 * b0 + c12 * b1 + c22 * b2) / det
        for j in range(3):
            a_own[k, j] = -(C[k, j, 0] * w0 + C[k, j, 1] * w1 + C[k, j, 2] * w2) / m[i]
            a_out[i, j] += a_own[k, j]


def face_impedances(part, elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""The impedances :math:`\rho_0 c_d` and :math:`\rho_0 c_s` [kg/(m^2 s)] (F,) of
    the elements ``elements`` (F,) of the solid part ``part``: each element's
    material's reference density and elastic constants (``part.groups``),
    :math:`c_d` its P-wave speed (the material's ``wave_speed``),
    :math:`c_s = \sqrt{G/\rho_0}`."""
    ne = part.el.n
    z_d, z_s = np.zeros(ne), np.zeros(ne)
    for g in part.groups:
        rows = np.unique(part.pts.elem[g.idx])
        rho0 = g.model.density(g.params)
        z_d[rows] = rho0 * g.model.wave_speed(g.params, rho0)
        z_s[rows] = math.sqrt(rho0 * g.model.shear_modulus(g.params))
    return np.ascontiguousarray(z_d[elements]), np.ascontiguousarray(z_s[elements])


class NonReflectingBoundary(FaceInteraction):
    """Viscous (Lysmer-Kuhlemeyer) dashpots on faces of a solid mesh part
    (module docstring).

    Parameters
    ----------
    name : column prefix.
    part : a solid mesh part (``kin``, ``el.active``, ``groups``).
    faces : (F, 4) quadrilaterals or (F, 2) segments, outward node order;
        ``elements`` (F,) their elements.

    Columns: ``<name>_absorbed`` the energy carried out so far [J] (J/m in 2D),
    ``<name>_force_x|y|z`` the dashpots' resultant now [N]. Its work is
    external work (``W_external``).
    """

    def __init__(self, name: str, part, faces, elements):
        super().__init__(name, part, faces, elements, "a non-reflecting boundary")
        self.z_d, self.z_s = face_impedances(part, self.elements)
        self.C = np.zeros((self.nodes.size, 3, 3))  # dashpot matrices now [kg/s]

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        q = self.part.kin
        boundary_dashpots(q.x, self.faces, self.local, self.elements,
                          self.part.el.active, self.z_d, self.z_s, self._S, self.C)
        # q.a holds the internal accelerations here (the stepper adds a_ext after
        # every interaction's forces)
        dashpot_accelerations(self.nodes, q.m, self.C, q.v, q.a, dt, self._a, a_out)

    def columns(self, t: float) -> dict[str, float]:
        f = (self.part.kin.m[self.nodes, None] * self._a).sum(axis=0)
        out = {f"{self.name}_absorbed": -self.work}
        for k, c in enumerate("xyz"):
            out[f"{self.name}_force_{c}"] = float(f[k])
        return out
