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
:func:`reference_gradients`. The passes are limited by memory traffic, so a
pair stores only its neighbour index and two 4-byte factors (kernel factor
and hourglass stiffness); the gradient vector is rebuilt from the reference
positions and the correction is applied per particle, outside the pair
loops.

References
----------
Ganzenmüller (2015), An hourglass control algorithm for Lagrangian Smooth
Particle Hydrodynamics, CMAME 286, 87-106.
Bonet & Lok (1999), CMAME 180, 97-115 (corrected gradients).

The model and its tests: docs/theory.md, "Total-Lagrangian SPH".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...algebra3 import det9, inverse3, load3, load9
from ...kernels import dwdq_over_q, kernel_value, support_nb

_DET_TOL = 1e-12

# The pair loops carry no floating-point licences (fastmath): with
# reassociation and contraction, LLVM's code for a kernel compiled in the
# process and the same kernel loaded from Numba's on-disk cache rounded
# differently, so a deck's last bits depended on whether the cache was warm
# (the 600 m/s penetration stopped in one process and ran through in another:
# tests/test_reproducible.py). Strict IEEE order costs the 2D rings nothing
# measurable (BENCHMARKS.md).


@njit(cache=True, error_model="numpy", parallel=True)
def reference_gradients(rows, X, h0, vol, offsets, idx, kid, sigma, dim, support_scale, fac, w,
                        B0, gsum):
    r"""Reference kernel factors, kernel values, correction matrices and gradient sums.

    The reference gradient of pair ``k = (i, j)`` is stored as one scalar,
    :math:`\mathbf g_{ij} = \mathrm{fac}_k (\mathbf X_i - \mathbf X_j)` with
    :math:`\mathrm{fac}_k = W'(R_{ij})/R_{ij} \le 0`, in single precision:
    the passes are limited by memory traffic, and 4 bytes per pair instead of
    the 48 of two corrected gradient vectors make them about twice as fast.
    The correction matrices are built from the *rounded* factors, so
    :math:`B_i` still makes the gradients exact for linear fields to double
    precision round-off, and ``fac`` is symmetric in the pair (momentum is
    conserved exactly).

    Parameters
    ----------
    rows : (T,) the total-Lagrangian particles; only their rows of ``B0``
        and ``gsum`` are written (the others' pages are never touched, so
        an (N, ...) array costs memory only for them).
    X : (N, 3) reference positions [m].
    h0 : (N,) reference smoothing lengths [m].
    vol : (N,) reference volumes m / rho0 [m^dim] (0 for zero-mass particles).
    offsets, idx : the fixed (reference) CSR neighbour list.
    kid, sigma, dim, support_scale : kernel id, normalisation, dimension, support scale.
    fac : (nnz,) float32 out, :math:`W'(R)/R` [1/m^(d+2)].
    w : (nnz,) out, :math:`W_{ij}` [1/m^d] (for hourglass control).
    B0 : (N, 3, 3) out, correction matrices
        :math:`B_i = [\sum_j V_j (\mathbf X_j - \mathbf X_i)\otimes\mathbf g_{ij}]^{-T}`
        (identity where the neighbourhood is degenerate; z row/column identity in 2D).
    gsum : (N, 3) out, :math:`\sum_j V_j \mathbf g_{ij}` [1/m] (zero in the
        interior of a regular lattice; the particle's own share of the
        stress divergence, see :func:`tl_forces`).
    """
    qmax = support_nb(kid)
    for t in prange(rows.shape[0]):
        i = rows[t]
        m00 = m01 = m02 = m10 = m11 = m12 = m20 = m21 = m22 = 0.0
        s0 = s1 = s2 = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            d0 = X[i, 0] - X[j, 0]
            d1 = X[i, 1] - X[j, 1]
            d2 = X[i, 2] - X[j, 2]
            r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            hij = support_scale * 0.5 * (h0[i] + h0[j])
            if r >= qmax * hij:
                fac[k] = 0.0
                w[k] = 0.0
                continue
            ih = 1.0 / hij
            fac[k] = sigma * ih ** (dim + 2) * dwdq_over_q(kid, r * ih)
            w[k] = kernel_value(kid, sigma, dim, r, hij)
            f = vol[j] * np.float64(fac[k])
            g0 = f * d0
            g1 = f * d1
            g2 = f * d2
            s0 += g0
            s1 += g1
            s2 += g2
            # (X_j - X_i) = -d
            m00 -= d0 * g0
            m01 -= d0 * g1
            m02 -= d0 * g2
            m10 -= d1 * g0
            m11 -= d1 * g1
            m12 -= d1 * g2
            m20 -= d2 * g0
            m21 -= d2 * g1
            m22 -= d2 * g2
        if dim == 2:
            m02 = m12 = m20 = m21 = 0.0
            m22 = 1.0
            s2 = 0.0
        inv = np.empty((3, 3))
        inverse3(m00, m01, m02, m10, m11, m12, m20, m21, m22, inv, _DET_TOL)
        for a in range(3):
            for b in range(3):
                B0[i, a, b] = inv[b, a]  # B = M^{-T}
        if dim == 2:  # exact identity in z (F_zz = 1 to the bit)
            B0[i, 0, 2] = B0[i, 1, 2] = B0[i, 2, 0] = B0[i, 2, 1] = 0.0
            B0[i, 2, 2] = 1.0
        gsum[i, 0] = s0
        gsum[i, 1] = s1
        gsum[i, 2] = s2


@njit(cache=True, error_model="numpy", parallel=True)
def deformation_gradient(rows, x, v, X, vol, offsets, idx, fac, B0, dim, Fdef, Finv, L):
    r"""Deformation gradient and velocity gradient from the reference kernel.

    .. math::
        F_i = \sum_j V_j (\mathbf x_j - \mathbf x_i) \otimes B_i \mathbf g_{ij}
            = \Big[\sum_j V_j\, \mathrm{fac}_{ij}\,
              (\mathbf x_j - \mathbf x_i) \otimes (\mathbf X_i - \mathbf X_j)\Big] B_i^T,

    likewise :math:`\dot F_i` with velocities, and :math:`L_i = \dot F_i
    F_i^{-1}` (exact for linear motions thanks to :math:`B_i`). The
    correction is applied once per particle, after the pair sum. ``x``, ``v``,
    ``X`` (N, 3) current positions, velocities and reference positions;
    ``vol`` (N,) reference volumes; ``fac`` and ``B0`` from
    :func:`reference_gradients`. Only the particles ``rows`` (int64 indices)
    are evaluated; ``Fdef``, ``Finv`` (its inverse) and ``L`` (N, 3, 3) are
    written in those rows only; in 2D ``F_zz = 1``. ``L`` feeds the same
    material kernels as the updated-Lagrangian scheme (Jaumann update of the
    Cauchy stress).
    """
    three = dim == 3
    # the row prologue (state of i unpacked into scalars) has the shape of the
    # updated-Lagrangian ``passes.forces``: same gather pattern, other scheme
    for t in prange(rows.shape[0]):
        i = rows[t]
        xi0, xi1, xi2 = load3(x, i)
        vi0, vi1, vi2 = load3(v, i)
        Xi0, Xi1, Xi2 = load3(X, i)
        # uncorrected sums A (positions) and D (velocities)
        a00 = a01 = a10 = a11 = 0.0
        e00 = e01 = e10 = e11 = 0.0
        a02 = a12 = a20 = a21 = a22 = 0.0
        e02 = e12 = e20 = e21 = e22 = 0.0
        k0 = offsets[i]
        k1 = offsets[i + 1]
        # deliberate 2D/3D variant pair (``duplicates`` lists it): two loops
        # instead of a dimension test per pair (about 1.5x faster)
        if three:
            for k in range(k0, k1):
                j = idx[k]
                f = vol[j] * np.float64(fac[k])
                g0 = f * (Xi0 - X[j, 0])
                g1 = f * (Xi1 - X[j, 1])
                g2 = f * (Xi2 - X[j, 2])
                dx0 = x[j, 0] - xi0
                dx1 = x[j, 1] - xi1
                dx2 = x[j, 2] - xi2
                dv0 = v[j, 0] - vi0
                dv1 = v[j, 1] - vi1
                dv2 = v[j, 2] - vi2
                a00 += dx0 * g0
                a01 += dx0 * g1
                a02 += dx0 * g2
                a10 += dx1 * g0
                a11 += dx1 * g1
                a12 += dx1 * g2
                a20 += dx2 * g0
                a21 += dx2 * g1
                a22 += dx2 * g2
                e00 += dv0 * g0
                e01 += dv0 * g1
                e02 += dv0 * g2
                e10 += dv1 * g0
                e11 += dv1 * g1
                e12 += dv1 * g2
                e20 += dv2 * g0
                e21 += dv2 * g1
                e22 += dv2 * g2
        else:
            for k in range(k0, k1):
                j = idx[k]
                f = vol[j] * np.float64(fac[k])
                g0 = f * (Xi0 - X[j, 0])
                g1 = f * (Xi1 - X[j, 1])
                dx0 = x[j, 0] - xi0
                dx1 = x[j, 1] - xi1
                dv0 = v[j, 0] - vi0
                dv1 = v[j, 1] - vi1
                a00 += dx0 * g0
                a01 += dx0 * g1
                a10 += dx1 * g0
                a11 += dx1 * g1
                e00 += dv0 * g0
                e01 += dv0 * g1
                e10 += dv1 * g0
                e11 += dv1 * g1
            a22 = 1.0  # F_zz = 1 with B_zz = 1
        _finish_gradients(i, a00, a01, a02, a10, a11, a12, a20, a21, a22,
                          e00, e01, e02, e10, e11, e12, e20, e21, e22, B0, Fdef, Finv, L)


@njit(cache=True, error_model="numpy")
def _finish_gradients(i, a00, a01, a02, a10, a11, a12, a20, a21, a22,
                      e00, e01, e02, e10, e11, e12, e20, e21, e22, B0, Fdef, Finv, L):
    r"""Row ``i`` of :func:`deformation_gradient` from the uncorrected sums A (``a..``)
    and D (``e..``): :math:`F = A B^T`, :math:`\dot F = D B^T`, ``Finv`` =
    :math:`F^{-1}` and :math:`L = \dot F F^{-1}` (zero if F is singular)."""
    for s in range(3):
        b0 = B0[i, s, 0]
        b1 = B0[i, s, 1]
        b2 = B0[i, s, 2]
        Fdef[i, 0, s] = a00 * b0 + a01 * b1 + a02 * b2
        Fdef[i, 1, s] = a10 * b0 + a11 * b1 + a12 * b2
        Fdef[i, 2, s] = a20 * b0 + a21 * b1 + a22 * b2
        L[i, 0, s] = e00 * b0 + e01 * b1 + e02 * b2
        L[i, 1, s] = e10 * b0 + e11 * b1 + e12 * b2
        L[i, 2, s] = e20 * b0 + e21 * b1 + e22 * b2
    f00, f01, f02, f10, f11, f12, f20, f21, f22 = load9(Fdef, i)
    det = inverse3(f00, f01, f02, f10, f11, f12, f20, f21, f22, Finv[i], _DET_TOL)
    for r in range(3):
        t0 = L[i, r, 0]
        t1 = L[i, r, 1]
        t2 = L[i, r, 2]
        for s in range(3):
            if det != 0.0:
                L[i, r, s] = t0 * Finv[i, 0, s] + t1 * Finv[i, 1, s] + t2 * Finv[i, 2, s]
            else:
                L[i, r, s] = 0.0


@njit(cache=True, error_model="numpy", parallel=True)
def tl_density(rows, Fdef, rho0, h0, rho, h):
    r"""Mass balance of the total-Lagrangian scheme, :math:`\rho = \rho_0 / \det F`.

    Rows ``rows`` of ``rho`` (N,) [kg/m^3] are overwritten (left unchanged
    where :math:`\det F \le 0`, i.e. an inverted neighbourhood the guards
    report); the smoothing length stays the reference one, ``h = h0`` (the
    kernel lives in the reference configuration).
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        det = det9(Fdef, i)
        if det > 0.0:
            rho[i] = rho0[i] / det
        h[i] = h0[i]


@njit(cache=True, error_model="numpy", parallel=True)
def piola_stress(rows, Fdef, Finv, sig, vol, B0, P, Q):
    r"""First Piola-Kirchhoff stress :math:`P = J \sigma F^{-T}`, :math:`J = \det F`,
    and its corrected, volume-weighted form :math:`Q = V P B`.

    ``Fdef``, ``Finv`` (from :func:`deformation_gradient`), ``sig`` (Cauchy,
    tension positive), ``P`` (N, 3, 3) out [Pa]; ``vol`` (N,) reference
    volumes, ``B0`` (N, 3, 3) correction matrices, ``Q`` (N, 3, 3) out
    [Pa m^dim], the factor of particle ``j`` in every pair sum of
    :func:`tl_forces`. Rows ``rows`` are evaluated.
    """
    for t in prange(rows.shape[0]):
        i = rows[t]
        det = det9(Fdef, i)
        for a in range(3):
            for b in range(3):
                P[i, a, b] = det * (sig[i, a, 0] * Finv[i, b, 0] + sig[i, a, 1] * Finv[i, b, 1]
                                    + sig[i, a, 2] * Finv[i, b, 2])
        for a in range(3):
            for b in range(3):
                Q[i, a, b] = vol[i] * (P[i, a, 0] * B0[i, 0, b] + P[i, a, 1] * B0[i, 1, b]
                                       + P[i, a, 2] * B0[i, 2, b])


@njit(cache=True, error_model="numpy", inline="always")
def _viscous_hourglass(fk, hk, d0, d1, d2, w0, w1, w2, s0, s1, s2, hij, csum, rhosum, mj,
                       av_alpha, av_beta):
    r"""Pair terms of :func:`tl_forces` beyond the stress: returns ``(mpf, coef)``.

    ``mpf`` = :math:`m_j \Pi_{ij}\,\mathrm{fac}_{ij}` (viscous acceleration
    :math:`-\mathrm{mpf}\,(\mathbf x_i - \mathbf x_j)`; zero for separating
    pairs, without a branch) and ``coef`` = hgk :math:`(\mathbf s\cdot\mathbf
    d)/|\mathbf d|^2` (hourglass force ``coef * d``), with one division for
    both: :math:`\mu = h v_x / D`, :math:`D = r^2 + 0.01 h^2`,
    :math:`\Pi = (-\alpha \bar c \mu + \beta \mu^2)/\bar\rho`.
    """
    r2 = max(d0 * d0 + d1 * d1 + d2 * d2, 1e-300)
    vx = min(w0 * d0 + w1 * d1 + w2 * d2, 0.0)
    den = r2 + 0.01 * hij * hij
    hv = hij * vx
    # Pi = 2 (-alpha csum/2 hv den + beta hv^2) / (den^2 rhosum)
    inv = 1.0 / (den * den * rhosum * r2)
    pi_ij = (-av_alpha * csum * hv * den + 2.0 * av_beta * hv * hv) * r2 * inv
    coef = hk * (s0 * d0 + s1 * d1 + s2 * d2) * (den * den * rhosum) * inv
    return mj * pi_ij * fk, coef


@njit(cache=True, error_model="numpy", inline="always")
def _row_sums(i, three, x, v, X, m, rho, c, h0, offsets, idx, fac, hgk, Q, Fdef, av_alpha,
              av_beta, support_scale):
    """Row ``i``'s pair sums of :func:`tl_forces`: ``(a0, a1, a2)``, the sum
    of fac Q_j (X_i - X_j); ``(q0, q1, q2)``, the viscous acceleration;
    ``(fh0, fh1, fh2)``, the hourglass force [N]; ``heat``, the viscous
    heating rate [W/kg]. The arrays come one by one, unpacked by the kernel
    outside its loop (unpacked here, in the loop, the TL rings ran 3 %
    slower: docs/architecture.md, "Numba conventions")."""
    xi0, xi1, xi2 = load3(x, i)
    vi0, vi1, vi2 = load3(v, i)
    ci = c[i]
    rhoi = rho[i]
    hi = h0[i]
    f00, f01, f02, f10, f11, f12, f20, f21, f22 = load9(Fdef, i)
    Xi0, Xi1, Xi2 = load3(X, i)
    a0 = a1 = a2 = 0.0  # sum_j fac Q_j (X_i - X_j)
    q0 = q1 = q2 = 0.0  # viscous acceleration
    fh0 = fh1 = fh2 = 0.0  # hourglass force [N]
    heat = 0.0
    k0 = offsets[i]
    k1 = offsets[i + 1]
    # deliberate 2D/3D variant pair (``duplicates`` lists it): two loops
    # instead of a dimension test per pair (about 1.5x faster)
    if three:
        for k in range(k0, k1):
            j = idx[k]
            fk = np.float64(fac[k])
            X0 = X[j, 0] - Xi0  # X_ij = X_j - X_i
            X1 = X[j, 1] - Xi1
            X2 = X[j, 2] - Xi2
            a0 -= fk * (Q[j, 0, 0] * X0 + Q[j, 0, 1] * X1 + Q[j, 0, 2] * X2)
            a1 -= fk * (Q[j, 1, 0] * X0 + Q[j, 1, 1] * X1 + Q[j, 1, 2] * X2)
            a2 -= fk * (Q[j, 2, 0] * X0 + Q[j, 2, 1] * X1 + Q[j, 2, 2] * X2)
            d0 = xi0 - x[j, 0]  # d = x_i - x_j = -x_ij
            d1 = xi1 - x[j, 1]
            d2 = xi2 - x[j, 2]
            # s = (F_i + F_j) X_ij - 2 x_ij
            s0 = ((f00 + Fdef[j, 0, 0]) * X0 + (f01 + Fdef[j, 0, 1]) * X1
                  + (f02 + Fdef[j, 0, 2]) * X2 + 2.0 * d0)
            s1 = ((f10 + Fdef[j, 1, 0]) * X0 + (f11 + Fdef[j, 1, 1]) * X1
                  + (f12 + Fdef[j, 1, 2]) * X2 + 2.0 * d1)
            s2 = ((f20 + Fdef[j, 2, 0]) * X0 + (f21 + Fdef[j, 2, 1]) * X1
                  + (f22 + Fdef[j, 2, 2]) * X2 + 2.0 * d2)
            w0 = vi0 - v[j, 0]
            w1 = vi1 - v[j, 1]
            w2 = vi2 - v[j, 2]
            mpf, coef = _viscous_hourglass(
                fk, np.float64(hgk[k]), d0, d1, d2, w0, w1, w2, s0, s1, s2,
                support_scale * 0.5 * (hi + h0[j]), ci + c[j], rhoi + rho[j], m[j],
                av_alpha, av_beta)
            q0 -= mpf * d0
            q1 -= mpf * d1
            q2 -= mpf * d2
            heat += 0.5 * mpf * min(w0 * d0 + w1 * d1 + w2 * d2, 0.0)
            fh0 += coef * d0
            fh1 += coef * d1
            fh2 += coef * d2
    else:
        for k in range(k0, k1):
            j = idx[k]
            fk = np.float64(fac[k])
            X0 = X[j, 0] - Xi0
            X1 = X[j, 1] - Xi1
            a0 -= fk * (Q[j, 0, 0] * X0 + Q[j, 0, 1] * X1)
            a1 -= fk * (Q[j, 1, 0] * X0 + Q[j, 1, 1] * X1)
            d0 = xi0 - x[j, 0]
            d1 = xi1 - x[j, 1]
            s0 = (f00 + Fdef[j, 0, 0]) * X0 + (f01 + Fdef[j, 0, 1]) * X1 + 2.0 * d0
            s1 = (f10 + Fdef[j, 1, 0]) * X0 + (f11 + Fdef[j, 1, 1]) * X1 + 2.0 * d1
            w0 = vi0 - v[j, 0]
            w1 = vi1 - v[j, 1]
            mpf, coef = _viscous_hourglass(
                fk, np.float64(hgk[k]), d0, d1, 0.0, w0, w1, 0.0, s0, s1, 0.0,
                support_scale * 0.5 * (hi + h0[j]), ci + c[j], rhoi + rho[j], m[j],
                av_alpha, av_beta)
            q0 -= mpf * d0
            q1 -= mpf * d1
            heat += 0.5 * mpf * min(w0 * d0 + w1 * d1, 0.0)
            fh0 += coef * d0
            fh1 += coef * d1
    return a0, a1, a2, q0, q1, q2, fh0, fh1, fh2, heat


@njit(cache=True, error_model="numpy", inline="always")
def _own_share(i, P, B0, gsum):
    r"""Row ``i``'s own share of :func:`tl_forces`, :math:`P_i B_i\,\mathbf{gsum}_i`."""
    # own share P_i B_i gsum_i
    pb0 = pb1 = pb2 = 0.0
    for s in range(3):
        gs = gsum[i, s]
        pb0 += (P[i, 0, 0] * B0[i, 0, s] + P[i, 0, 1] * B0[i, 1, s]
                + P[i, 0, 2] * B0[i, 2, s]) * gs
        pb1 += (P[i, 1, 0] * B0[i, 0, s] + P[i, 1, 1] * B0[i, 1, s]
                + P[i, 1, 2] * B0[i, 2, s]) * gs
        pb2 += (P[i, 2, 0] * B0[i, 0, s] + P[i, 2, 1] * B0[i, 1, s]
                + P[i, 2, 2] * B0[i, 2, s]) * gs
    return pb0, pb1, pb2


@njit(cache=True, error_model="numpy", parallel=True)
def tl_forces(rows, kin, props, pairs, stress, dim, viscosity, a, dedt_av):
    r"""Acceleration of the total-Lagrangian scheme with hourglass control.

    Momentum balance :math:`\rho_0 \dot{\mathbf v} = \nabla_X\cdot P` in the
    antisymmetric (momentum-conserving) pair form

    .. math::
        \dot{\mathbf v}_i = \frac{1}{\rho_{0i}} \sum_j V_j
            \big(P_i B_i + P_j B_j\big)\, \mathbf g_{ij}
            - \sum_j m_j \Pi_{ij} \mathbf G_{ij}
            + \frac{\mathbf f^{hg}_i}{m_i},

    evaluated as :math:`\rho_{0i}\dot{\mathbf v}_i = P_i B_i\,
    \mathbf{gsum}_i + \sum_j \mathrm{fac}_{ij}\, Q_j (\mathbf X_i -
    \mathbf X_j)` with :math:`\mathbf g_{ij} = \mathrm{fac}_{ij}(\mathbf X_i
    - \mathbf X_j)`, :math:`Q_j = V_j P_j B_j` (:func:`piola_stress`) and
    the reference sum ``gsum`` of :func:`reference_gradients`: the pair loop
    reads one 4-byte factor per pair.

    *Artificial viscosity* (Monaghan 1992, as in the updated-Lagrangian
    :func:`sphdyn.parts.sph.passes.forces`) with the current pair separation
    :math:`\mathbf x_{ij}`, velocity :math:`\mathbf v_{ij}`, density
    :math:`\rho = \rho_0/J` and the reference smoothing length, acting along
    the current line of centres with the reference kernel factor,
    :math:`\mathbf G_{ij} = \frac{W'(R_{ij})}{R_{ij}} (\mathbf x_i - \mathbf
    x_j)`: the updated-Lagrangian form with the kernel factor frozen at the
    reference distance, so the viscous pair force is central (linear and
    angular momentum conserved) and dissipative; the heating rate is
    :math:`\dot e_i = \tfrac12\sum_j m_j \Pi_{ij} \mathbf v_{ij}\cdot
    \mathbf G_{ij}`. It is evaluated without a branch (:math:`\Pi_{ij} = 0`
    for separating pairs through :math:`\min(\mathbf v_{ij}\cdot\mathbf
    x_{ij}, 0)`), which avoids a mispredicted jump on every other pair, and
    with one division per pair for viscosity and hourglass together
    (:func:`_viscous_hourglass`).

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
    ``hgk`` of :func:`hourglass_coefficients` is all it needs per pair. Its
    power :math:`-\mathbf f^{hg}_i\cdot\mathbf v_i / m_i` is added to
    ``dedt_av`` so that the energy balance closes (hourglass work is
    book-kept with the viscous heat).

    Parameters
    ----------
    rows : (n_tl,) int64, the particles evaluated (rows of ``a`` and
        ``dedt_av`` written; other rows untouched).
    kin : ``(x, v, X)``, (N, 3) current positions [m], velocities [m/s],
        reference positions.
    props : ``(m, rho, rho0, c, h0, vol)``, (N,) mass [kg], current and
        reference density [kg/m^3], wave speed [m/s], reference smoothing
        length [m], reference volume m/rho0.
    pairs : ``(offsets, idx, fac, hgk)``: the reference pairs (CSR) and
        their kernel factors from :func:`reference_gradients`; ``hgk``
        (nnz,) float32 hourglass pair factors from
        :func:`hourglass_coefficients` (all zero = hourglass control off).
    stress : ``(P, Q, B0, Fdef, gsum)``: (N, 3, 3) first Piola-Kirchhoff
        stress [Pa] and V P B (:func:`piola_stress`), the correction B0 and
        the reference sums ``gsum`` (:func:`reference_gradients`), the
        deformation gradient.
    dim : 2 or 3 (2: z components skipped; they are zero).
    viscosity : ``(av_alpha, av_beta, support_scale)``, the artificial
        viscosity's coefficients and the kernel's support scale.
    a : (N, 3) out, acceleration [m/s^2].
    dedt_av : (N,) out, viscous + hourglass heating rate [W/kg].

    The inputs come grouped in tuples, the arrays it writes one by one
    (docs/architecture.md, "Numba conventions").
    """
    x, v, X = kin
    m, rho, rho0, c, h0, _ = props
    offsets, idx, fac, hgk = pairs
    P, Q, B0, Fdef, gsum = stress
    av_alpha, av_beta, support_scale = viscosity
    three = dim == 3
    for t in prange(rows.shape[0]):
        i = rows[t]
        a0, a1, a2, q0, q1, q2, fh0, fh1, fh2, heat = _row_sums(
            i, three, x, v, X, m, rho, c, h0, offsets, idx, fac, hgk, Q, Fdef, av_alpha,
            av_beta, support_scale)
        pb0, pb1, pb2 = _own_share(i, P, B0, gsum)
        inv_rho0 = 1.0 / rho0[i]
        a[i, 0] = (a0 + pb0) * inv_rho0 + q0
        a[i, 1] = (a1 + pb1) * inv_rho0 + q1
        a[i, 2] = (a2 + pb2) * inv_rho0 + q2
        if m[i] > 0.0:
            a[i, 0] += fh0 / m[i]
            a[i, 1] += fh1 / m[i]
            a[i, 2] += fh2 / m[i]
            heat -= (fh0 * v[i, 0] + fh1 * v[i, 1] + fh2 * v[i, 2]) / m[i]
        dedt_av[i] = heat


@njit(cache=True, error_model="numpy", parallel=True)
def hourglass_coefficients(rows, X, vol, offsets, idx, w, young, alpha, hgk):
    r"""Reference pair factors of Ganzenmüller's (2015) hourglass force.

    .. math:: \mathrm{hgk}_{ij} = -\frac{\alpha}{2}\,
              \frac{V_i V_j W_{ij}\, \tfrac12 (E_i + E_j)}{|\mathbf X_{ij}|^2}

    for the pairs of ``rows`` (the force is then ``hgk`` times
    :math:`(\delta^i+\delta^j)\hat{\mathbf x}_{ij}`, see :func:`tl_forces`).
    ``X`` (N, 3) reference positions [m], ``vol`` (N,) reference volumes,
    ``w`` (nnz,) reference kernel values, ``young`` (N,) Young's moduli
    [Pa], ``alpha`` the dimensionless coefficient; ``hgk`` (nnz,) out
    [N/m^2 in 3D] (float32 in the solver, like ``fac``: a stiffness factor
    needs no more digits, and the force pass reads it for every pair).
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
