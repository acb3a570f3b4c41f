r"""The velocity-gradient pass of the updated-Lagrangian SPH solid scheme:
:math:`\mathbf L_i = \frac{1}{\rho_i}\sum_j m_j (\mathbf v_j - \mathbf v_i)
\otimes \mathbf g_{ij} B_i^T` with the correction matrix :math:`B_i`
(Randles & Libersky 1996) and the pair factors the force pass reuses; the
scheme, its pairing with the forces and the references: :mod:`.passes`.
Rows are gathered in ``prange`` and written only by their owner (race-free);
long rows go through a row buffer of :data:`GRADIENT_ROWS` rows in
:data:`GRADIENT_CHUNKS` chunks (:func:`gradient_scratch`).

The model and its tests: docs/theory.md, "Updated-Lagrangian SPH for solids".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...algebra3 import inverse_sym3, load3
from ...kernels import dwdq_over_q, support_nb
from ...simd import sqrt as simd_sqrt


# Determinant below which the correction matrix is treated as singular
# (isolated particle or a neighbourhood on a line); the raw gradient is used then.
_DET_TOL = 1e-6


@njit(cache=True, error_model="numpy", inline="always")
def _gradient_row(i, x, v, h, m, rho, offsets, idx, n_own, kid, sigma, dim, support_scale,
                  correct, F, L, B, count):
    """Row ``i`` of :func:`velocity_gradient` (its docstring); inlined into
    each of the pass's compiled forms, where ``kid``, ``dim`` and ``correct``
    may be constants."""
    qmax = support_nb(kid)
    l00 = l01 = l02 = l10 = l11 = l12 = l20 = l21 = l22 = 0.0
    # the moment matrix (symmetric: its upper triangle)
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    xi0, xi1, xi2 = load3(x, i)
    vi0, vi1, vi2 = load3(v, i)
    three = dim == 3
    hi = h[i]
    irho = 1.0 / rho[i]
    o = offsets[i]
    for part in range(2):  # the own pairs, then the others (own_pairs_first)
        lo = o if part == 0 else o + n_own[i]
        head = lo  # next slot of the part's head (pairs within the support)
        for k in range(lo, o + n_own[i] if part == 0 else offsets[i + 1]):
            j = idx[k]
            d0 = xi0 - x[j, 0]
            d1 = xi1 - x[j, 1]
            d2 = xi2 - x[j, 2] if three else 0.0
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            hij = support_scale * 0.5 * (hi + h[j])
            if r2 >= (qmax * hij) ** 2:
                F[k] = 0.0
                continue
            # grad_factor with one division: sigma / h^(d+2) * w'(q)/q
            ih = 1.0 / hij
            ih2 = ih * ih
            if dim == 1:
                scale = sigma * ih2 * ih
            else:
                scale = sigma * ih2 * ih2
                if three:
                    scale *= ih
            # stored in single precision, and used as stored from here on
            fk = np.float64(np.float32(scale * dwdq_over_q(kid, np.sqrt(r2) * ih)))
            if k != head:  # swap with the part's first skin pair
                idx[k] = idx[head]
                F[k] = 0.0
                idx[head] = j
            F[head] = fk
            head += 1
            f = fk * (m[j] * irho)
            if f == 0.0:
                continue
            g0 = f * d0
            g1 = f * d1
            u0 = v[j, 0] - vi0
            u1 = v[j, 1] - vi1
            # components unrolled: the in-plane terms here and the z terms
            # below (3D only) have the same shape (a deliberate pair)
            l00 += u0 * g0
            l01 += u0 * g1
            l10 += u1 * g0
            l11 += u1 * g1
            if correct:  # (x_j - x_i) = -d
                m00 -= d0 * g0
                m01 -= d0 * g1
                m11 -= d1 * g1
            if three:
                g2 = f * d2
                u2 = v[j, 2] - vi2
                l02 += u0 * g2
                l12 += u1 * g2
                l20 += u2 * g0
                l21 += u2 * g1
                l22 += u2 * g2
                if correct:
                    m02 -= d0 * g2
                    m12 -= d1 * g2
                    m22 -= d2 * g2
        if part == 0:
            count[i] = head - o
    finish_row(i, dim, correct, l00, l01, l02, l10, l11, l12, l20, l21, l22,
               m00, m01, m02, m11, m12, m22, L, B)


@njit(cache=True, error_model="numpy", inline="always")
def finish_row(i, dim, correct, l00, l01, l02, l10, l11, l12, l20, l21, l22,
               m00, m01, m02, m11, m12, m22, L, B):
    """Row ``i``'s ``L`` and ``B`` from its sums (:func:`velocity_gradient`):
    the correction ``Q = M^-1`` of the moment matrix ``M`` (upper triangle
    ``m..``) when ``correct``, and ``L = L_raw Q``, ``B = Q``."""
    # Q = M^{-1} (symmetric, as M is): L_true = L_raw Q, B = Q^T = Q
    q00 = q11 = q22 = 1.0
    q01 = q02 = q12 = 0.0
    if correct:
        if dim < 3:
            m02 = m12 = 0.0
            m22 = 1.0
        if dim == 1:
            m01 = 0.0
            m11 = 1.0
        q00, q01, q02, q11, q12, q22 = inverse_sym3(m00, m01, m02, m11, m12, m22, _DET_TOL)
    L[i, 0, 0] = l00 * q00 + l01 * q01 + l02 * q02
    L[i, 0, 1] = l00 * q01 + l01 * q11 + l02 * q12
    L[i, 0, 2] = l00 * q02 + l01 * q12 + l02 * q22
    L[i, 1, 0] = l10 * q00 + l11 * q01 + l12 * q02
    L[i, 1, 1] = l10 * q01 + l11 * q11 + l12 * q12
    L[i, 1, 2] = l10 * q02 + l11 * q12 + l12 * q22
    L[i, 2, 0] = l20 * q00 + l21 * q01 + l22 * q02
    L[i, 2, 1] = l20 * q01 + l21 * q11 + l22 * q12
    L[i, 2, 2] = l20 * q02 + l21 * q12 + l22 * q22
    B[i, 0, 0] = q00
    B[i, 0, 1] = q01
    B[i, 0, 2] = q02
    B[i, 1, 0] = q01
    B[i, 1, 1] = q11
    B[i, 1, 2] = q12
    B[i, 2, 0] = q02
    B[i, 2, 1] = q12
    B[i, 2, 2] = q22


#: rows of a chunk's row buffer in :func:`_buffered_row` (pair ``t`` of the
#: row within the support in column ``t``): r^2, h_j and the kernel factor
_R2, _HJ, _FK = range(3)
GRADIENT_ROWS = 3


#: contiguous particle chunks of the buffered pass (each a row buffer)
GRADIENT_CHUNKS = 64


def gradient_scratch(offsets, scratch=None):
    """Row buffers (GRADIENT_CHUNKS, GRADIENT_ROWS, width) of :func:`velocity_gradient`'s
    buffered forms, ``width`` the longest row of the CSR list ``offsets``
    ((N + 1,)): ``scratch`` itself when it is wide enough (called after each
    neighbour rebuild; a longer row than the buffer is worked without it)."""
    width = int(np.max(np.diff(offsets))) if offsets.shape[0] > 1 else 0
    if scratch is not None and scratch.shape[2] >= width:
        return scratch
    return np.zeros((GRADIENT_CHUNKS, GRADIENT_ROWS, int(width * 1.2) + 8))


@njit(cache=True, error_model="numpy", inline="always")
def _buffered_row(i, x, v, h, m, rho, offsets, idx, n_own, sigma, support_scale, correct, F, L,
                  B, count, W):
    """Row ``i`` of :func:`velocity_gradient` for the 3D cubic spline, the same
    operations in the same order as :func:`_gradient_row` (the same bits),
    in three loops: (1) the partition of the row's two parts, keeping
    ``r^2`` and ``h_j`` of the pairs within the support in the row buffer
    ``W`` (GRADIENT_ROWS, width), (2) their kernel factors, pair by pair
    independent, which the compiler turns into SIMD instructions, into the
    buffer, (3) the row's sums, in the row's order, the factors stored in
    ``F`` there and the neighbours' positions and velocities read again.
    Three numbers per pair go through the buffer, not the sums' twelve: the
    first loop was bound by its stores (BENCHMARKS.md, 2026-11-28 later),
    and reading a neighbour again, just read, costs less."""
    xi0, xi1, xi2 = load3(x, i)
    vi0, vi1, vi2 = load3(v, i)
    hi = h[i]
    irho = 1.0 / rho[i]
    o = offsets[i]
    own = o + n_own[i]  # the second part's first slot
    t = 0  # pairs within the support so far, both parts
    for part in range(2):  # the own pairs, then the others (own_pairs_first)
        head = o if part == 0 else own
        for k in range(head, own if part == 0 else offsets[i + 1]):
            j = idx[k]
            d0 = xi0 - x[j, 0]
            d1 = xi1 - x[j, 1]
            d2 = xi2 - x[j, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            hj = h[j]
            if r2 >= (support_nb(0) * (support_scale * 0.5 * (hi + hj))) ** 2:
                F[k] = 0.0
                continue
            if k != head:  # swap with the part's first skin pair
                idx[k] = idx[head]
                F[k] = 0.0
                idx[head] = j
            W[_R2, t] = r2
            W[_HJ, t] = hj
            head += 1
            t += 1
        if part == 0:
            count[i] = t
    c0 = count[i]
    end = head  # the second part's pairs within the support: own to end
    for t in range(c0 + end - own):  # the kernel factors, into the buffer
        W[_FK, t] = _buffered_factor(W, t, hi, sigma, support_scale)
    l00 = l01 = l02 = l10 = l11 = l12 = l20 = l21 = l22 = 0.0
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    t = 0
    for part in range(2):
        for k in range(o if part == 0 else own, o + c0 if part == 0 else end):
            fk = W[_FK, t]
            t += 1
            F[k] = fk
            j = idx[k]
            f = fk * (m[j] * irho)
            if f == 0.0:
                continue
            d0 = xi0 - x[j, 0]
            d1 = xi1 - x[j, 1]
            d2 = xi2 - x[j, 2]
            g0 = f * d0
            g1 = f * d1
            g2 = f * d2
            u0 = v[j, 0] - vi0
            u1 = v[j, 1] - vi1
            u2 = v[j, 2] - vi2
            l00 += u0 * g0
            l01 += u0 * g1
            l02 += u0 * g2
            l10 += u1 * g0
            l11 += u1 * g1
            l12 += u1 * g2
            l20 += u2 * g0
            l21 += u2 * g1
            l22 += u2 * g2
            if correct:  # (x_j - x_i) = -d
                m00 -= d0 * g0
                m01 -= d0 * g1
                m02 -= d0 * g2
                m11 -= d1 * g1
                m12 -= d1 * g2
                m22 -= d2 * g2
    finish_row(i, 3, correct, l00, l01, l02, l10, l11, l12, l20, l21, l22,
               m00, m01, m02, m11, m12, m22, L, B)


@njit(cache=True, error_model="numpy", inline="always")
def _buffered_factor(W, t, hi, sigma, support_scale):
    """Kernel factor (rounded to float32) of pair ``t`` of the row buffer ``W`` of
    :func:`_buffered_row` (3D cubic spline): ``sigma / h^5 * w'(q)/q``; the
    kernel's own ``w'(q)/q``, inlined: both pieces formed, one selected."""
    ih = 1.0 / (support_scale * 0.5 * (hi + W[_HJ, t]))
    ih2 = ih * ih
    scale = sigma * ih2 * ih2
    scale *= ih
    return np.float64(np.float32(scale * dwdq_over_q(0, simd_sqrt(W[_R2, t]) * ih)))


@njit(cache=True, error_model="numpy", inline="always")
def _buffered_chunk(t, x, v, h, m, rho, offsets, idx, n_own, sigma, support_scale, correct, F,
                    L, B, count, work):
    """Chunk ``t`` of :data:`GRADIENT_CHUNKS` (contiguous particles) of the
    buffered pass; a row longer than the buffer takes :func:`_gradient_row`."""
    n = x.shape[0]
    W = work[t]
    for i in range(t * n // GRADIENT_CHUNKS, (t + 1) * n // GRADIENT_CHUNKS):
        if offsets[i + 1] - offsets[i] <= W.shape[1]:
            _buffered_row(i, x, v, h, m, rho, offsets, idx, n_own, sigma, support_scale,
                          correct, F, L, B, count, W)
        else:
            _gradient_row(i, x, v, h, m, rho, offsets, idx, n_own, 0, sigma, 3, support_scale,
                          correct, F, L, B, count)


@njit(cache=True, error_model="numpy", parallel=True)
def velocity_gradient(x, v, h, m, rho, offsets, idx, n_own, kid, sigma, dim, support_scale,
                      correct, F, L, B, count, work):
    r"""Velocity gradient with optional Randles-Libersky renormalisation.

    .. math::
        L_i = \sum_j \frac{m_j}{\rho_i} (\mathbf v_j - \mathbf v_i) \otimes
              \mathbf g_{ij}\, B_i^T,
        \qquad
        B_i = \Big[\sum_j \frac{m_j}{\rho_i} (\mathbf x_j - \mathbf x_i) \otimes
              \mathbf g_{ij}\Big]^{-T}

    (``L[i, a, b] = dv_a/dx_b``). Without correction ``B_i = I``. With it, any
    linear velocity field is differentiated exactly at every particle that
    has a non-degenerate neighbourhood (Randles & Libersky 1996). In 2D the
    z row and column of the moment matrix are set to the identity, in 1D
    (uniaxial strain along x, every y and z zero) the y ones too. The moment
    matrix is symmetric, :math:`\sum_j (m_j/\rho_i) F_{ij}\, \mathbf d \otimes
    \mathbf d` with :math:`\mathbf d = \mathbf x_i - \mathbf x_j`, so its six
    distinct entries are summed (and ``B_i`` is symmetric), and only when the
    correction is on.

    Speed: the row's sums are kept in registers; the pass is compiled in
    four forms (correction on or off, and the 3D cubic spline or any kernel
    and dimension), picked outside the particle loop, so the common cases
    carry no branch on the kernel or the dimension and no moment sums they
    do not use (BENCHMARKS.md, 2026-11-26: a spilled sum cost more than its
    arithmetic). The 3D cubic-spline forms work each row through a row
    buffer (:func:`_buffered_row`): the kernel factors of a row's pairs,
    independent of each other, are formed in SIMD instructions; the sums
    keep the row's order, so the bits are those of the pair-by-pair row
    (BENCHMARKS.md, 2026-11-27 later and 2026-11-28 later).

    The pass also stores the kernel-gradient factor of every pair,

    .. math:: \nabla_i W(\mathbf x_i - \mathbf x_j, h_{ij}) = F_{ij}\,
              (\mathbf x_i - \mathbf x_j), \qquad
              F_{ij} = \frac{1}{r}\frac{\partial W}{\partial r}

    (see :func:`sphdyn.kernels.grad_factor`), which :func:`.passes.forces` reuses, so the
    kernel is evaluated once per pair and step. Pairs in the Verlet skin are
    rejected on ``r^2`` (no square root or kernel call) and get ``F = 0``.

    The pass also orders each row, in two parts: the row's first
    ``n_own[i]`` pairs (its own pairs, :func:`~sphdyn.parts.sph.colouring.own_pairs_first`)
    and the rest. In each part the pairs within the support come first, in
    the order they had (a stable partition of the part in place; the row
    still holds the same neighbours, so the Verlet list stays valid);
    ``count[i]`` of them in the first part. :func:`.passes.forces` visits only those,
    not the skin's pairs nor the pairs it works from the other row, and the
    sums over a row keep their order while its pairs stay within the
    support. With ``n_own`` the row lengths the rows are one part:
    ``count`` is then every pair within the support.

    Parameters
    ----------
    x, v : (N, 3) positions [m] and velocities [m/s].
    h : (N,) smoothing length [m].
    m, rho : (N,) masses [kg] (0 for zero-mass particles) and densities
        [kg/m^3]; the weight of pair ij is m_j / rho_i (the energy partner of
        :func:`.passes.forces`, see the module docstring).
    offsets, idx : CSR neighbour list (``idx`` (nnz,) int32, each row
        reordered in place, see above).
    n_own : (N,) int32, the length of each row's first part (see above).
    kid, sigma, dim, support_scale : kernel id, normalisation, dimension (2: z
        terms skipped; 1: y and z zero), support scale kappa.
    correct : bool, apply the renormalisation.
    F : (nnz,) float32 out, pair gradient factors [1/m^(d+2)], aligned with
        ``idx``. Single precision halves the list's largest array (memory at
        the drop-weight's full size, BENCHMARKS.md); ``L`` and ``B`` are
        summed from the rounded factors, so the pairing of ``L`` with the
        force pass (the energy balance) and the exact gradient of linear
        fields hold to double-precision round-off, as for the
        total-Lagrangian scheme's factors (a deliberate numerical choice:
        the factors differ from the double ones by 3e-8 relative at most).
    L : (N, 3, 3) out, velocity gradient [1/s].
    B : (N, 3, 3) out, correction matrix applied to kernel gradients
        (identity when ``correct`` is False).
    count : (N,) int32 out, pairs within the support at the head of row i
        (of its first part).
    work : (GRADIENT_CHUNKS, GRADIENT_ROWS, width) scratch of the buffered forms
        (:func:`gradient_scratch`).
    """
    n = x.shape[0]
    # constants in the common forms (the cubic spline is kernel 0); the
    # same row in each
    if dim == 3 and kid == 0:
        if correct:
            for t in prange(GRADIENT_CHUNKS):
                _buffered_chunk(t, x, v, h, m, rho, offsets, idx, n_own, sigma, support_scale,
                                True, F, L, B, count, work)
        else:
            for t in prange(GRADIENT_CHUNKS):
                _buffered_chunk(t, x, v, h, m, rho, offsets, idx, n_own, sigma, support_scale,
                                False, F, L, B, count, work)
    elif correct:
        for i in prange(n):
            _gradient_row(i, x, v, h, m, rho, offsets, idx, n_own, kid, sigma, dim,
                          support_scale, True, F, L, B, count)
    else:
        for i in prange(n):
            _gradient_row(i, x, v, h, m, rho, offsets, idx, n_own, kid, sigma, dim,
                          support_scale, False, F, L, B, count)
