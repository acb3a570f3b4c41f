r"""Artificial stress against the tensile instability (Monaghan 2000; Gray et al. 2001).

Each particle gets a small repulsive stress :math:`R_i` built from the tensile
principal stresses only,

.. math::
    \sigma_i = Q_i \,\mathrm{diag}(\sigma'_1, \sigma'_2, \sigma'_3)\, Q_i^T,
    \qquad
    R'_{aa} = \begin{cases} -\varepsilon\, \sigma'_{aa} / \rho_i^2 &
              \sigma'_{aa} > 0 \ \text{(tension)} \\ 0 & \text{otherwise}
              \end{cases},
    \qquad
    R_i = Q_i\, \mathrm{diag}(R'_{11}, R'_{22}, R'_{33})\, Q_i^T,

(Gray, Monaghan & Swift 2001, eqs. 4.7-4.9; stress positive in tension there
and here), and the momentum equation gains

.. math::
    \dot{\mathbf v}_i \mathrel{+}= \sum_j m_j\, f_{ij}^{\,n}\,
        (R_i + R_j)\, \nabla_i W_{ij},
    \qquad
    f_{ij} = \frac{W(r_{ij}, h_{ij})}{W(\Delta p_{ij}, h_{ij})}
           = \frac{w(r_{ij}/h_{ij})}{w(\Delta p_{ij}/h_{ij})}

(Monaghan 2000, eq. 4.6). :math:`\Delta p_{ij}` is the mean initial particle
spacing of the pair (``vol0**(1/dim)``) and :math:`h_{ij}` the same pair
smoothing length as in :mod:`sphdyn.parts.sph.passes` (support scale included), so
the normalisation :math:`\sigma_d/h^d` cancels in :math:`f_{ij}`. Because
:math:`R_i` is negative definite where the material is in tension, the term
is an extra pressure that grows steeply (:math:`f^n`) when two particles
approach each other closer than the initial spacing, which is exactly the
clumping mode of the instability; at the initial spacing it is
:math:`\varepsilon` times the tensile stress. Gray et al. use
:math:`\varepsilon = 0.3`, :math:`n = 4`.

The pair term uses the raw kernel gradient (also when the solver applies the
Randles-Libersky correction to the stress term) so that pair forces are
antisymmetric and linear momentum is conserved to round-off.

References
----------
Monaghan, J.J. (2000). SPH without a tensile instability. J. Comput. Phys.
    159, 290-311.
Gray, J.P., Monaghan, J.J., Swift, R.P. (2001). SPH elastic dynamics.
    Comput. Methods Appl. Mech. Engrg. 190, 6641-6662.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...kernels import w

__all__ = ["artificial_stress_tensor", "artificial_stress_forces"]

# Jacobi sweeps for the 3x3 symmetric eigenproblem; cyclic Jacobi converges
# quadratically, 3x3 needs 4-6 sweeps to round-off.
_MAX_SWEEPS = 12


@njit(cache=True, error_model="numpy", parallel=True)
def artificial_stress_tensor(sig, rho, eps, R, Q):
    r"""Artificial stress :math:`R_i` (N, 3, 3) [Pa m^6/kg^2] of every particle.

    Principal axes by cyclic Jacobi rotations (no allocation: ``R[i]`` is the
    work matrix and ``Q[i]`` the eigenvectors), then
    :math:`R_i = Q_i\,\mathrm{diag}(-\varepsilon \max(\sigma'_a, 0)/\rho_i^2)\,Q_i^T`
    (Gray, Monaghan & Swift 2001, eqs. 4.7-4.9).

    Parameters
    ----------
    sig : (N, 3, 3) Cauchy stress [Pa], tension positive, symmetric.
    rho : (N,) density [kg/m^3].
    eps : (N,) epsilon >= 0 per particle (dimensionless; 0.3 in Gray et al.;
        0 switches the remedy off for that particle, e.g. per body).
    R : (N, 3, 3) out, artificial stress divided by rho^2 [Pa m^6/kg^2]
        (negative semi-definite).
    Q : (N, 3, 3) work/out, principal directions as columns.
    """
    n = sig.shape[0]
    for i in prange(n):
        A = R[i]
        V = Q[i]
        for a in range(3):
            for b in range(3):
                A[a, b] = 0.5 * (sig[i, a, b] + sig[i, b, a])
                V[a, b] = 1.0 if a == b else 0.0
        scale = abs(A[0, 0]) + abs(A[1, 1]) + abs(A[2, 2]) \
            + abs(A[0, 1]) + abs(A[0, 2]) + abs(A[1, 2])
        if scale == 0.0 or eps[i] == 0.0:
            for a in range(3):
                for b in range(3):
                    A[a, b] = 0.0
            continue
        for _sweep in range(_MAX_SWEEPS):
            off = abs(A[0, 1]) + abs(A[0, 2]) + abs(A[1, 2])
            if off <= 1e-15 * scale:
                break
            for p in range(2):
                for q in range(p + 1, 3):
                    apq = A[p, q]
                    if apq == 0.0:
                        continue
                    # rotation angle zeroing A[p, q] (Golub & Van Loan, sec. 8.5)
                    theta = (A[q, q] - A[p, p]) / (2.0 * apq)
                    t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
                    if theta < 0.0:
                        t = -t
                    c = 1.0 / np.sqrt(t * t + 1.0)
                    s = t * c
                    for k in range(3):  # A <- A J
                        akp = A[k, p]
                        akq = A[k, q]
                        A[k, p] = c * akp - s * akq
                        A[k, q] = s * akp + c * akq
                    for k in range(3):  # A <- J^T A
                        apk = A[p, k]
                        aqk = A[q, k]
                        A[p, k] = c * apk - s * aqk
                        A[q, k] = s * apk + c * aqk
                    for k in range(3):  # V <- V J
                        vkp = V[k, p]
                        vkq = V[k, q]
                        V[k, p] = c * vkp - s * vkq
                        V[k, q] = s * vkp + c * vkq
        f = -eps[i] / (rho[i] * rho[i])
        r0 = f * A[0, 0] if A[0, 0] > 0.0 else 0.0
        r1 = f * A[1, 1] if A[1, 1] > 0.0 else 0.0
        r2 = f * A[2, 2] if A[2, 2] > 0.0 else 0.0
        for a in range(3):
            for b in range(a, 3):
                val = r0 * V[a, 0] * V[b, 0] + r1 * V[a, 1] * V[b, 1] \
                    + r2 * V[a, 2] * V[b, 2]
                A[a, b] = val
                A[b, a] = val


@njit(cache=True, error_model="numpy", parallel=True)
def artificial_stress_forces(x, m, h, R, F, offsets, idx, kid, dim, support_scale, spacing,
                             n_exp, a, v, dedt):
    r"""Add the artificial-stress acceleration to ``a`` (gather form).

    .. math::
        \mathbf a_i \mathrel{+}= \sum_j m_j\, f_{ij}^{\,n}\,
            (R_i + R_j)\, \nabla_i W_{ij}, \qquad
        f_{ij} = \frac{w(r_{ij}/h_{ij})}{w(\Delta p_{ij}/h_{ij})}

    (Monaghan 2000, eq. 4.6; Gray et al. 2001, eq. 4.10) with
    :math:`h_{ij} = \kappa (h_i + h_j)/2` and
    :math:`\Delta p_{ij} = (\Delta p_i + \Delta p_j)/2`. The pair term is
    antisymmetric in ``i, j``, so momentum is conserved to round-off.

    Parameters
    ----------
    x : (N, 3) positions [m].
    m, h : (N,) mass [kg] (kg/m in 2D), smoothing length [m].
    R : (N, 3, 3) from :func:`artificial_stress_tensor` [Pa m^6/kg^2].
    F : (nnz,) pair gradient factors from
        :func:`sphdyn.parts.sph.gradient.velocity_gradient` [1/m^(d+2)]
        (``grad_i W_ij = F_ij (x_i - x_j)``).
    offsets, idx : CSR neighbour list.
    kid, dim, support_scale : kernel id, dimension, support scale kappa.
    spacing : (N,) initial particle spacing vol0**(1/dim) [m].
    n_exp : float, exponent n (4 in Gray et al.).
    a : (N, 3) in/out, acceleration [m/s^2].
    v : (N, 3) velocities [m/s].
    dedt : (N,) in/out, heating rate [W/kg]: :math:`-\mathbf a^{AS}_i\cdot
        \mathbf v_i` is added, so that the work of the artificial stress is
        booked with the viscous and hourglass heat and the energy balance
        closes (:math:`\sum_i m_i \dot e_i = -\sum_i m_i \mathbf a^{AS}_i
        \cdot\mathbf v_i`, the power of these forces).
    """
    n = x.shape[0]
    three = dim == 3
    # integer exponents (the usual n = 4) by repeated squaring, not pow()
    n_int = int(n_exp)
    is_int = float(n_int) == n_exp
    # the pair-loop prologue (skip zero gradients and zero masses) is that of
    # ``passes.forces``: same gather pattern over the same pair factors F
    for i in prange(n):
        a0 = a1 = a2 = 0.0
        hi = h[i]
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            fk = F[k]
            mj = m[j]
            if fk == 0.0 or mj == 0.0:
                continue
            t00 = R[i, 0, 0] + R[j, 0, 0]
            t01 = R[i, 0, 1] + R[j, 0, 1]
            t11 = R[i, 1, 1] + R[j, 1, 1]
            if three:
                t02 = R[i, 0, 2] + R[j, 0, 2]
                t12 = R[i, 1, 2] + R[j, 1, 2]
                t22 = R[i, 2, 2] + R[j, 2, 2]
            else:
                t02 = t12 = t22 = 0.0
            if (t00 == 0.0 and t01 == 0.0 and t11 == 0.0 and t02 == 0.0
                    and t12 == 0.0 and t22 == 0.0):
                continue  # neither particle in tension
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2] if three else 0.0
            hij = support_scale * 0.5 * (hi + h[j])
            ih = 1.0 / hij
            w_ref = w(kid, 0.5 * (spacing[i] + spacing[j]) * ih)
            if w_ref <= 0.0:
                continue
            r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            fij = w(kid, r * ih) / w_ref
            if is_int:
                fn = 1.0
                base = fij
                e = n_int
                while e > 0:
                    if e & 1:
                        fn *= base
                    base *= base
                    e >>= 1
            else:
                fn = fij ** n_exp
            coef = mj * fn * fk
            g0 = coef * d0
            g1 = coef * d1
            g2 = coef * d2
            a0 += t00 * g0 + t01 * g1
            a1 += t01 * g0 + t11 * g1
            if three:
                a0 += t02 * g2
                a1 += t12 * g2
                a2 += t02 * g0 + t12 * g1 + t22 * g2
        a[i, 0] += a0
        a[i, 1] += a1
        a[i, 2] += a2
        dedt[i] -= a0 * v[i, 0] + a1 * v[i, 1] + a2 * v[i, 2]
