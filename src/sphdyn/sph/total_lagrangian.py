r"""Total-Lagrangian SPH passes (the thesis's "Lagrangian kernel", sec. 2.2.1).

Neighbours and kernel gradients are fixed in the reference configuration
:math:`\mathbf X` (the initial positions), so the kernel deforms with the
material and the tensile instability of the updated-Lagrangian kernel cannot
occur (thesis sec. 3.2; Belytschko et al. 2000; Ganzenmüller 2015).
Notation: :math:`\mathbf g_{ij} = \nabla_{X_i} W(\mathbf X_i - \mathbf X_j,
h_{ij})`, reference volumes :math:`V_j = m_j / \rho_{0j}` and the reference
correction matrix

.. math:: B_i = \Big[\sum_j V_j (\mathbf X_j - \mathbf X_i) \otimes
          \mathbf g_{ij}\Big]^{-T},

so that :math:`\tilde{\mathbf g}_{ij} = B_i \mathbf g_{ij}` differentiates
linear fields exactly. Everything reference-related is computed once by
:func:`reference_gradients`.

References
----------
Ganzenmüller (2015), An hourglass control algorithm for Lagrangian Smooth
Particle Hydrodynamics, CMAME 286, 87-106.
Bonet & Lok (1999), CMAME 180, 97-115 (corrected gradients).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..kernels import dwdq_over_q, kernel_value, support_nb

_DET_TOL = 1e-12


@njit(cache=True)
def _inverse3(a00, a01, a02, a10, a11, a12, a20, a21, a22, out):
    """Inverse of a 3x3 matrix into ``out`` (3, 3); identity if singular."""
    c00 = a11 * a22 - a12 * a21
    c01 = a02 * a21 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a10 * c01 + a20 * c02
    if abs(det) < _DET_TOL:
        for r in range(3):
            for s in range(3):
                out[r, s] = 1.0 if r == s else 0.0
        return 0.0
    inv = 1.0 / det
    out[0, 0] = c00 * inv
    out[0, 1] = c01 * inv
    out[0, 2] = c02 * inv
    out[1, 0] = (a12 * a20 - a10 * a22) * inv
    out[1, 1] = (a00 * a22 - a02 * a20) * inv
    out[1, 2] = (a02 * a10 - a00 * a12) * inv
    out[2, 0] = (a10 * a21 - a11 * a20) * inv
    out[2, 1] = (a01 * a20 - a00 * a21) * inv
    out[2, 2] = (a00 * a11 - a01 * a10) * inv
    return det


@njit(cache=True, parallel=True)
def reference_gradients(X, h0, vol, offsets, idx, kid, sigma, dim, kscale, g, w, B0):
    r"""Reference kernel gradients, kernel values and correction matrices.

    Parameters
    ----------
    X : (N, 3) reference positions [m].
    h0 : (N,) reference smoothing lengths [m].
    vol : (N,) reference volumes m / rho0 [m^dim] (0 for zero-mass particles).
    offsets, idx : the fixed (reference) CSR neighbour list.
    kid, sigma, dim, kscale : kernel id, normalisation, dimension, support scale.
    g : (nnz, 3) out, :math:`\nabla_{X_i} W_{ij}` [1/m^(d+1)].
    w : (nnz,) out, :math:`W_{ij}` [1/m^d] (for hourglass control).
    B0 : (N, 3, 3) out, correction matrices :math:`B_i` (identity where the
        neighbourhood is degenerate; z row/column identity in 2D).
    """
    n = X.shape[0]
    qmax = support_nb(kid)
    for i in prange(n):
        m00 = m01 = m02 = m10 = m11 = m12 = m20 = m21 = m22 = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            d0 = X[i, 0] - X[j, 0]
            d1 = X[i, 1] - X[j, 1]
            d2 = X[i, 2] - X[j, 2]
            r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            hij = kscale * 0.5 * (h0[i] + h0[j])
            if r >= qmax * hij:
                g[k, 0] = g[k, 1] = g[k, 2] = 0.0
                w[k] = 0.0
                continue
            ih = 1.0 / hij
            f = sigma * ih ** (dim + 2) * dwdq_over_q(kid, r * ih)
            g[k, 0] = f * d0
            g[k, 1] = f * d1
            g[k, 2] = f * d2
            w[k] = kernel_value(kid, sigma, dim, r, hij)
            vj = vol[j]
            # (X_j - X_i) = -d
            m00 -= vj * d0 * g[k, 0]
            m01 -= vj * d0 * g[k, 1]
            m02 -= vj * d0 * g[k, 2]
            m10 -= vj * d1 * g[k, 0]
            m11 -= vj * d1 * g[k, 1]
            m12 -= vj * d1 * g[k, 2]
            m20 -= vj * d2 * g[k, 0]
            m21 -= vj * d2 * g[k, 1]
            m22 -= vj * d2 * g[k, 2]
        if dim == 2:
            m02 = m12 = m20 = m21 = 0.0
            m22 = 1.0
        inv = np.empty((3, 3))
        _inverse3(m00, m01, m02, m10, m11, m12, m20, m21, m22, inv)
        for a in range(3):
            for b in range(3):
                B0[i, a, b] = inv[b, a]  # B = M^{-T}


@njit(cache=True, parallel=True)
def corrected_pair_gradients(X, offsets, idx, g, B0, gi, gj, fac):
    r"""Corrected reference gradients of both ends of every pair, once.

    ``gi[k] = B_i g_ij`` and ``gj[k] = B_j g_ij`` (nnz, 3), so the force pass
    evaluates :math:`(P_i B_i + P_j B_j)\, \mathbf g_{ij} = P_i\,
    \mathbf{gi}_k + P_j\, \mathbf{gj}_k` with 18 multiply-adds per pair;
    ``fac[k]`` (nnz,) is the scalar with :math:`\mathbf g_{ij} =
    \mathrm{fac}_k (\mathbf X_i - \mathbf X_j)`, i.e. :math:`W'(R)/R` at the
    reference distance (<= 0), used by the artificial viscosity. ``X`` (N, 3)
    reference positions [m].
    """
    for i in prange(offsets.shape[0] - 1):
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            g0 = g[k, 0]
            g1 = g[k, 1]
            g2 = g[k, 2]
            for a in range(3):
                gi[k, a] = B0[i, a, 0] * g0 + B0[i, a, 1] * g1 + B0[i, a, 2] * g2
                gj[k, a] = B0[j, a, 0] * g0 + B0[j, a, 1] * g1 + B0[j, a, 2] * g2
            d0 = X[i, 0] - X[j, 0]
            d1 = X[i, 1] - X[j, 1]
            d2 = X[i, 2] - X[j, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            fac[k] = (g0 * d0 + g1 * d1 + g2 * d2) / r2 if r2 > 0.0 else 0.0


@njit(cache=True, parallel=True)
def deformation_gradient(rows, x, v, vol, offsets, idx, gi, dim, Fdef, Finv, L):
    r"""Deformation gradient and velocity gradient from the reference kernel.

    .. math::
        F_i = \sum_j V_j (\mathbf x_j - \mathbf x_i) \otimes \tilde{\mathbf g}_{ij},
        \qquad
        \dot F_i = \sum_j V_j (\mathbf v_j - \mathbf v_i) \otimes
                   \tilde{\mathbf g}_{ij},
        \qquad L_i = \dot F_i F_i^{-1}

    (exact for linear motions thanks to :math:`B_i`), with
    :math:`\tilde{\mathbf g}_{ij}` = ``gi`` from
    :func:`corrected_pair_gradients`. Only the particles
    ``rows`` (int64 indices) are evaluated; ``Fdef``, ``Finv`` (its inverse)
    and ``L`` (N, 3, 3) are written in those rows only; in 2D ``F_zz = 1``.
    ``L`` feeds the same material kernels as the updated-Lagrangian scheme
    (Jaumann update of the Cauchy stress). No allocation: ``L`` holds
    :math:`\dot F` until the product is formed row by row.
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        for a in range(3):
            for b in range(3):
                Fdef[i, a, b] = 0.0
                L[i, a, b] = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            vj = vol[j]
            if vj == 0.0:
                continue
            gt0 = gi[k, 0]
            gt1 = gi[k, 1]
            gt2 = gi[k, 2]
            for a in range(3):
                dx = vj * (x[j, a] - x[i, a])
                dv = vj * (v[j, a] - v[i, a])
                Fdef[i, a, 0] += dx * gt0
                Fdef[i, a, 1] += dx * gt1
                Fdef[i, a, 2] += dx * gt2
                L[i, a, 0] += dv * gt0
                L[i, a, 1] += dv * gt1
                L[i, a, 2] += dv * gt2
        if dim == 2:
            Fdef[i, 0, 2] = Fdef[i, 1, 2] = Fdef[i, 2, 0] = Fdef[i, 2, 1] = 0.0
            Fdef[i, 2, 2] = 1.0
            L[i, 0, 2] = L[i, 1, 2] = L[i, 2, 0] = L[i, 2, 1] = L[i, 2, 2] = 0.0
        det = _inverse3(Fdef[i, 0, 0], Fdef[i, 0, 1], Fdef[i, 0, 2], Fdef[i, 1, 0],
                        Fdef[i, 1, 1], Fdef[i, 1, 2], Fdef[i, 2, 0], Fdef[i, 2, 1],
                        Fdef[i, 2, 2], Finv[i])
        for a in range(3):
            t0 = L[i, a, 0]
            t1 = L[i, a, 1]
            t2 = L[i, a, 2]
            for b in range(3):
                if det != 0.0:
                    L[i, a, b] = t0 * Finv[i, 0, b] + t1 * Finv[i, 1, b] + t2 * Finv[i, 2, b]
                else:
                    L[i, a, b] = 0.0


@njit(cache=True)
def _det(F, i):
    """Determinant of ``F[i]`` (3, 3)."""
    return (F[i, 0, 0] * (F[i, 1, 1] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 1])
            - F[i, 0, 1] * (F[i, 1, 0] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 0])
            + F[i, 0, 2] * (F[i, 1, 0] * F[i, 2, 1] - F[i, 1, 1] * F[i, 2, 0]))


@njit(cache=True, parallel=True)
def tl_density(rows, Fdef, rho0, h0, rho, h):
    r"""Mass balance of the total-Lagrangian scheme, :math:`\rho = \rho_0 / \det F`.

    Rows ``rows`` of ``rho`` (N,) [kg/m^3] are overwritten (left unchanged
    where :math:`\det F \le 0`, i.e. an inverted neighbourhood the guards
    report); the smoothing length stays the reference one, ``h = h0`` (the
    kernel lives in the reference configuration).
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        det = _det(Fdef, i)
        if det > 0.0:
            rho[i] = rho0[i] / det
        h[i] = h0[i]


@njit(cache=True, parallel=True)
def piola_stress(rows, Fdef, Finv, sig, P):
    r"""First Piola-Kirchhoff stress :math:`P = J \sigma F^{-T}`, :math:`J = \det F`.

    ``Fdef``, ``Finv`` (from :func:`deformation_gradient`), ``sig`` (Cauchy,
    tension positive), ``P`` (N, 3, 3) [Pa]; rows ``rows`` are evaluated.
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        det = _det(Fdef, i)
        for a in range(3):
            for b in range(3):
                P[i, a, b] = det * (sig[i, a, 0] * Finv[i, b, 0] + sig[i, a, 1] * Finv[i, b, 1]
                                    + sig[i, a, 2] * Finv[i, b, 2])


@njit(cache=True, parallel=True)
def tl_forces(rows, x, v, X, m, rho, rho0, c, h0, vol, offsets, idx, gi, gj, fac, hgk,
              P, Fdef, dim, av_alpha, av_beta, kscale, a, dedt_av):
    r"""Acceleration of the total-Lagrangian scheme with hourglass control.

    Momentum balance :math:`\rho_0 \dot{\mathbf v} = \nabla_X\cdot P` in the
    antisymmetric (momentum-conserving) pair form

    .. math::
        \dot{\mathbf v}_i = \frac{1}{\rho_{0i}} \sum_j V_j
            \big(P_i B_i + P_j B_j\big)\, \mathbf g_{ij}
            - \sum_j m_j \Pi_{ij} \mathbf G_{ij}
            + \frac{\mathbf f^{hg}_i}{m_i}.

    *Artificial viscosity* (Monaghan 1992, as in the updated-Lagrangian
    :func:`sphdyn.sph.passes.forces`) with the current pair separation
    :math:`\mathbf x_{ij}`, velocity :math:`\mathbf v_{ij}`, density
    :math:`\rho = \rho_0/J` and the reference smoothing length, acting along
    the current line of centres with the reference kernel factor,
    :math:`\mathbf G_{ij} = \frac{W'(R_{ij})}{R_{ij}} (\mathbf x_i - \mathbf
    x_j)` (:math:`R_{ij} = |\mathbf X_{ij}|`, ``fac`` below): the
    updated-Lagrangian form with the kernel factor frozen at the reference
    distance, so the viscous pair force is central (linear and angular
    momentum conserved) and dissipative; the heating rate is
    :math:`\dot e_i = \tfrac12\sum_j m_j \Pi_{ij} \mathbf v_{ij}\cdot
    \mathbf G_{ij}`.

    *Hourglass control* (Ganzenmüller 2015) penalises the part of the pair
    separation not predicted by the particles' own deformation gradients:
    with :math:`\mathbf X_{ij} = \mathbf X_j - \mathbf X_i`,
    :math:`\mathbf x_{ij} = \mathbf x_j - \mathbf x_i`,
    :math:`\delta^i_{ij} = (F_i \mathbf X_{ij} - \mathbf x_{ij})\cdot\hat{\mathbf x}_{ij}`
    and :math:`\delta^j_{ij} = (F_j \mathbf X_{ij} - \mathbf x_{ij})\cdot\hat{\mathbf x}_{ij}`,

    .. math::
        \mathbf f^{hg}_i = -\frac{\alpha}{2} \sum_j
            \frac{V_i V_j W_{ij} \bar E_{ij}}{|\mathbf X_{ij}|^2}
            (\delta^i_{ij} + \delta^j_{ij})\, \hat{\mathbf x}_{ij}.

    It vanishes for every linear deformation and is antisymmetric in the
    pair. Since :math:`(\delta^i + \delta^j)\hat{\mathbf x} =
    [((F_i + F_j)\mathbf X_{ij} - 2\mathbf x_{ij})\cdot\mathbf x_{ij}]\,
    \mathbf x_{ij} / |\mathbf x_{ij}|^2`, the reference factor
    ``hgk`` of :func:`hourglass_coefficients` is all it needs per pair. Its power :math:`-\mathbf f^{hg}_i\cdot\mathbf v_i / m_i` is added
    to ``dedt_av`` so that the energy balance closes (hourglass work is
    book-kept with the viscous heat).

    Parameters
    ----------
    rows : (n_tl,) int64, the particles evaluated (rows of ``a`` and
        ``dedt_av`` written; other rows untouched).
    x, v, X : (N, 3) current positions [m], velocities [m/s], reference positions.
    m, rho, rho0, c, h0, vol : (N,) mass [kg], current and reference density
        [kg/m^3], wave speed [m/s], reference smoothing length [m],
        reference volume m/rho0.
    gi, gj, fac : from :func:`corrected_pair_gradients`.
    hgk : (nnz,) hourglass pair factors from :func:`hourglass_coefficients`
        (all zero = hourglass control off).
    P, Fdef : (N, 3, 3) first Piola-Kirchhoff stress [Pa], deformation gradient.
    dim : 2 or 3 (2: z components skipped; they are zero).
    av_alpha, av_beta : artificial viscosity coefficients; kscale: support scale.
    a : (N, 3) out, acceleration [m/s^2].
    dedt_av : (N,) out, viscous + hourglass heating rate [W/kg].
    """
    visc = av_alpha > 0.0 or av_beta > 0.0
    three = dim == 3
    for t in prange(rows.shape[0]):
        i = rows[t]
        pi00 = P[i, 0, 0]
        pi01 = P[i, 0, 1]
        pi02 = P[i, 0, 2]
        pi10 = P[i, 1, 0]
        pi11 = P[i, 1, 1]
        pi12 = P[i, 1, 2]
        pi20 = P[i, 2, 0]
        pi21 = P[i, 2, 1]
        pi22 = P[i, 2, 2]
        xi0 = x[i, 0]
        xi1 = x[i, 1]
        xi2 = x[i, 2]
        vi0 = v[i, 0]
        vi1 = v[i, 1]
        vi2 = v[i, 2]
        ci = c[i]
        rhoi = rho[i]
        hi = h0[i]
        rho0i = rho0[i]
        f00 = Fdef[i, 0, 0]
        f01 = Fdef[i, 0, 1]
        f02 = Fdef[i, 0, 2]
        f10 = Fdef[i, 1, 0]
        f11 = Fdef[i, 1, 1]
        f12 = Fdef[i, 1, 2]
        f20 = Fdef[i, 2, 0]
        f21 = Fdef[i, 2, 1]
        f22 = Fdef[i, 2, 2]
        Xi0 = X[i, 0]
        Xi1 = X[i, 1]
        Xi2 = X[i, 2]
        a0 = a1 = a2 = 0.0  # stress part times rho0_i, viscous part [m/s^2]
        q0 = q1 = q2 = 0.0
        f0 = f1 = f2 = 0.0  # hourglass force [N]
        heat = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            vj = vol[j]
            fk = fac[k]
            if vj == 0.0 or fk == 0.0:
                continue
            # (P_i B_i + P_j B_j) g = P_i gi + P_j gj
            bi0 = gi[k, 0]
            bi1 = gi[k, 1]
            bj0 = gj[k, 0]
            bj1 = gj[k, 1]
            a0 += vj * (pi00 * bi0 + pi01 * bi1 + P[j, 0, 0] * bj0 + P[j, 0, 1] * bj1)
            a1 += vj * (pi10 * bi0 + pi11 * bi1 + P[j, 1, 0] * bj0 + P[j, 1, 1] * bj1)
            # current pair geometry d = x_i - x_j
            d0 = xi0 - x[j, 0]
            d1 = xi1 - x[j, 1]
            w0 = vi0 - v[j, 0]
            w1 = vi1 - v[j, 1]
            if three:
                bi2 = gi[k, 2]
                bj2 = gj[k, 2]
                a0 += vj * (pi02 * bi2 + P[j, 0, 2] * bj2)
                a1 += vj * (pi12 * bi2 + P[j, 1, 2] * bj2)
                a2 += vj * (pi20 * bi0 + pi21 * bi1 + pi22 * bi2
                            + P[j, 2, 0] * bj0 + P[j, 2, 1] * bj1 + P[j, 2, 2] * bj2)
                d2 = xi2 - x[j, 2]
                w2 = vi2 - v[j, 2]
            else:
                d2 = 0.0
                w2 = 0.0
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            if visc:
                vx = w0 * d0 + w1 * d1 + w2 * d2
                if vx < 0.0:
                    hij = kscale * 0.5 * (hi + h0[j])
                    mu = hij * vx / (r2 + 0.01 * hij * hij)
                    pi_ij = (-av_alpha * 0.5 * (ci + c[j]) * mu + av_beta * mu * mu) / (
                        0.5 * (rhoi + rho[j]))
                    # -m_j Pi G_ij, G_ij = fac (x_i - x_j)
                    mpf = m[j] * pi_ij * fk
                    q0 -= mpf * d0
                    q1 -= mpf * d1
                    q2 -= mpf * d2
                    heat += 0.5 * mpf * vx
            hk = hgk[k]
            if hk != 0.0 and r2 > 0.0:
                X0 = X[j, 0] - Xi0
                X1 = X[j, 1] - Xi1
                # s = (F_i + F_j) X_ij - 2 x_ij, with x_ij = x_j - x_i = -d
                s0 = (f00 + Fdef[j, 0, 0]) * X0 + (f01 + Fdef[j, 0, 1]) * X1 + 2.0 * d0
                s1 = (f10 + Fdef[j, 1, 0]) * X0 + (f11 + Fdef[j, 1, 1]) * X1 + 2.0 * d1
                s2 = 0.0
                if three:
                    X2 = X[j, 2] - Xi2
                    s0 += (f02 + Fdef[j, 0, 2]) * X2
                    s1 += (f12 + Fdef[j, 1, 2]) * X2
                    s2 = ((f20 + Fdef[j, 2, 0]) * X0 + (f21 + Fdef[j, 2, 1]) * X1
                          + (f22 + Fdef[j, 2, 2]) * X2 + 2.0 * d2)
                # hgk (s . x_ij) x_ij / r^2 = hgk (s . d) d / r^2
                coef = hk * (s0 * d0 + s1 * d1 + s2 * d2) / r2
                f0 += coef * d0
                f1 += coef * d1
                f2 += coef * d2
        inv_rho0 = 1.0 / rho0i
        a[i, 0] = a0 * inv_rho0 + q0
        a[i, 1] = a1 * inv_rho0 + q1
        a[i, 2] = a2 * inv_rho0 + q2
        if m[i] > 0.0:
            a[i, 0] += f0 / m[i]
            a[i, 1] += f1 / m[i]
            a[i, 2] += f2 / m[i]
            heat -= (f0 * vi0 + f1 * vi1 + f2 * vi2) / m[i]
        dedt_av[i] = heat


@njit(cache=True, parallel=True)
def hourglass_coefficients(rows, X, vol, offsets, idx, w, young, alpha, hgk):
    r"""Reference pair factors of Ganzenmüller's (2015) hourglass force.

    .. math:: \mathrm{hgk}_{ij} = -\frac{\alpha}{2}\,
              \frac{V_i V_j W_{ij}\, \tfrac12 (E_i + E_j)}{|\mathbf X_{ij}|^2}

    for the pairs of ``rows`` (the force is then ``hgk`` times
    :math:`(\delta^i+\delta^j)\hat{\mathbf x}_{ij}`, see :func:`tl_forces`).
    ``X`` (N, 3) reference positions [m], ``vol`` (N,) reference volumes,
    ``w`` (nnz,) reference kernel values, ``young`` (N,) Young's moduli
    [Pa], ``alpha`` the dimensionless coefficient; ``hgk`` (nnz,) out
    [N/m^2 in 3D].
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            d0 = X[j, 0] - X[i, 0]
            d1 = X[j, 1] - X[i, 1]
            d2 = X[j, 2] - X[i, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            if r2 == 0.0 or alpha == 0.0:
                hgk[k] = 0.0
            else:
                hgk[k] = -0.25 * alpha * vol[i] * vol[j] * w[k] * (young[i] + young[j]) / r2
