r"""Element erosion criteria: the strains of an element and the rules that erode it.

The element's deformation gradient at its centre (one-point, uniform
gradient of the reference configuration, Flanagan & Belytschko 1981):

.. math:: F_{ij} = \sum_I x_{iI}\, B^0_{jI}, \qquad
          B^0_{jI} = \frac{1}{V_0}\frac{\partial V}{\partial X_{jI}},

exact for a homogeneous deformation of any hexahedron (quadrilateral in
plane strain, with :math:`F_{zz} = 1`). From the principal stretches
:math:`\lambda_k` (square roots of the eigenvalues of :math:`C = F^TF`):

* maximum principal strain (engineering): :math:`\varepsilon_1 = \lambda_{max} - 1`;
* effective strain: the von Mises equivalent of the logarithmic strain,
  :math:`\varepsilon_{eff} = \sqrt{\tfrac23\sum_k (\ln\lambda_k - \bar e)^2}`,
  :math:`\bar e = \tfrac13\sum_k\ln\lambda_k` (:math:`\sqrt{\tfrac23 e':e'}`
  at small strain, LS-DYNA's EFFEPS of *MAT_ADD_EROSION).

Rules (an element erodes when any of its material's rules holds; codes in
the flag array):

1. :data:`BY_DAMAGE`, LS-DYNA *MAT_CSCM (MAT_159) ERODE: the element's mean
   damage exceeds 0.99 **and** :math:`\varepsilon_1 >` ERODE - 1;
2. :data:`BY_PRINCIPAL`: :math:`\varepsilon_1` above a limit;
3. :data:`BY_EFFECTIVE`: :math:`\varepsilon_{eff}` above a limit;
4. :data:`BY_TIME_STEP`: the element's stable step (with the part's factor)
   below a minimum.

The model and its tests: docs/theory.md, "Element erosion".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .solid import block_count, block_span, local_coordinates, volume_gradient

BY_DAMAGE = 1
BY_PRINCIPAL = 2
BY_EFFECTIVE = 3
BY_TIME_STEP = 4
REASONS = {BY_DAMAGE: "damage", BY_PRINCIPAL: "principal_strain",
           BY_EFFECTIVE: "effective_strain", BY_TIME_STEP: "time_step"}
#: the MAT_159 rule's damage threshold
DAMAGE_THRESHOLD = 0.99
#: columns of the per-element rule table of :func:`erosion_flags`
RULE_COLUMNS = ("principal_at_damage", "principal_strain", "effective_strain", "min_time_step")


@njit(cache=True, error_model="numpy")
def sym3_eigenvalues(a00, a01, a02, a11, a12, a22):
    r"""Eigenvalues (descending) of a symmetric 3 x 3 matrix, closed form.

    Trigonometric solution of the characteristic cubic (Smith 1961, CACM 4,
    168): with :math:`q = \operatorname{tr}A/3`, :math:`p = \sqrt{\|A -
    qI\|^2/6}`, :math:`r = \det((A - qI)/p)/2`, :math:`\varphi =
    \arccos(r)/3`: :math:`\lambda_1 = q + 2p\cos\varphi`, :math:`\lambda_3 =
    q + 2p\cos(\varphi + 2\pi/3)`, :math:`\lambda_2 = 3q - \lambda_1 - \lambda_3`.
    """
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    q = (a00 + a11 + a22) / 3.0
    b00 = a00 - q
    b11 = a11 - q
    b22 = a22 - q
    p2 = b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * p1
    if p2 <= 1e-30 * q * q:  # a multiple of the identity
        return q, q, q
    p = math.sqrt(p2 / 6.0)
    det = (b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02)
           + a02 * (a01 * a12 - b11 * a02))
    r = det / (2.0 * p * p * p)
    r = min(1.0, max(-1.0, r))
    phi = math.acos(r) / 3.0
    l1 = q + 2.0 * p * math.cos(phi)
    l3 = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    return l1, 3.0 * q - l1 - l3, l3


@njit(cache=True, error_model="numpy")
def strain_measures(F):
    r"""Maximum principal (engineering) strain and effective (logarithmic)
    strain of a deformation gradient ``F`` (3, 3) (module docstring)."""
    c00 = F[0, 0] * F[0, 0] + F[1, 0] * F[1, 0] + F[2, 0] * F[2, 0]  # C = F^T F
    c01 = F[0, 0] * F[0, 1] + F[1, 0] * F[1, 1] + F[2, 0] * F[2, 1]
    c02 = F[0, 0] * F[0, 2] + F[1, 0] * F[1, 2] + F[2, 0] * F[2, 2]
    c11 = F[0, 1] * F[0, 1] + F[1, 1] * F[1, 1] + F[2, 1] * F[2, 1]
    c12 = F[0, 1] * F[0, 2] + F[1, 1] * F[1, 2] + F[2, 1] * F[2, 2]
    c22 = F[0, 2] * F[0, 2] + F[1, 2] * F[1, 2] + F[2, 2] * F[2, 2]
    l1, l2, l3 = sym3_eigenvalues(c00, c01, c02, c11, c12, c22)
    tiny = 1e-300
    e1 = 0.5 * math.log(max(l1, tiny))
    e2 = 0.5 * math.log(max(l2, tiny))
    e3 = 0.5 * math.log(max(l3, tiny))
    mean = (e1 + e2 + e3) / 3.0
    eff = math.sqrt(2.0 / 3.0 * ((e1 - mean) ** 2 + (e2 - mean) ** 2 + (e3 - mean) ** 2))
    return math.sqrt(max(l1, 0.0)) - 1.0, eff


@njit(cache=True, error_model="numpy", parallel=True)
def reference_gradients(x0, conn, dim, tab, b0):
    r"""Uniform gradients :math:`B^0` (E, nen, 3) [1/m] of the reference
    configuration ``x0`` (N, 3) (module docstring)."""
    ne = conn.shape[0]
    for e in prange(ne):
        xl = np.empty((conn.shape[1], 3))
        local_coordinates(x0, x0, 0.0, conn, e, xl)
        v0 = volume_gradient(xl, dim, tab, b0[e])
        inv = 1.0 / v0 if v0 > 0.0 else 0.0
        for I in range(conn.shape[1]):
            for k in range(3):
                b0[e, I, k] *= inv


@njit(cache=True, error_model="numpy")
def deformation_gradient(x, conn, e, b0, dim, F):
    """``F`` (3, 3) of element ``e`` at the node positions ``x`` (module docstring)."""
    n0 = conn[e, 0]
    for i in range(3):
        for j in range(3):
            s = 0.0
            for I in range(conn.shape[1]):
                s += (x[conn[e, I], i] - x[n0, i]) * b0[e, I, j]
            F[i, j] = s
    if dim == 2:
        F[2, 2] = 1.0


@njit(cache=True, error_model="numpy", parallel=True)
def erosion_flags(x, conn, active, b0, dim, damage, ngp, dt_el, cfl, rules, flags, work):
    r"""Which active elements erode, and why (module docstring).

    ``damage`` (P,) point damage (``ngp`` points per element, the mean is
    the element's); ``dt_el`` (E,) element steps (times ``cfl``: the part's
    step); ``rules`` (E, 4) per element: ERODE - 1 of the damage rule, the
    principal-strain limit, the effective-strain limit (``inf`` where off)
    and the minimum step (0 where off). ``flags`` (E,) int8 out: 0, or the
    code of the first rule that holds; ``work`` (B, >= 3, 3) scratch per block
    (the part's :func:`~.solid.block_scratch`). Returns the number flagged.
    """
    ne = conn.shape[0]
    count = 0
    for b in prange(block_count(ne)):
        F = work[b, 0:3]
        lo, hi = block_span(b, ne)
        for e in range(lo, hi):
            flags[e] = 0
            if active[e] == 0:
                continue
            if cfl * dt_el[e] < rules[e, 3]:
                flags[e] = BY_TIME_STEP
                count += 1
                continue
            d = 0.0
            for k in range(ngp):
                d += damage[e * ngp + k]
            d /= ngp
            damaged = d > DAMAGE_THRESHOLD and rules[e, 0] < np.inf
            if not damaged and rules[e, 1] == np.inf and rules[e, 2] == np.inf:
                continue  # no rule can hold: no strain needed (most elements)
            deformation_gradient(x, conn, e, b0, dim, F)
            if rules[e, 2] == np.inf:
                # only principal strains asked: Gershgorin's bound on the
                # largest eigenvalue of C = F^T F spares the eigenvalues of
                # elements far from every limit
                bound = 0.0
                for i in range(3):
                    row = 0.0
                    for j in range(3):
                        cij = F[0, i] * F[0, j] + F[1, i] * F[1, j] + F[2, i] * F[2, j]
                        row += cij if i == j else abs(cij)
                    bound = max(bound, row)
                limit = min(rules[e, 1], rules[e, 0] if damaged else np.inf)
                if math.sqrt(max(bound, 0.0)) - 1.0 <= limit:
                    continue
            e1, eff = strain_measures(F)
            if damaged and e1 > rules[e, 0]:
                flags[e] = BY_DAMAGE
            elif e1 > rules[e, 1]:
                flags[e] = BY_PRINCIPAL
            elif eff > rules[e, 2]:
                flags[e] = BY_EFFECTIVE
            if flags[e]:
                count += 1
    return count
