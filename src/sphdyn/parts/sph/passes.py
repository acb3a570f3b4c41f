r"""SPH passes of the updated-Lagrangian ("Eulerian kernel") solid scheme.

Each pass but :func:`forces` loops over particles ``i`` in ``prange`` and over
the neighbours ``j`` of ``i`` (CSR rows ``idx[offsets[i]:offsets[i+1]]``) and
writes only row ``i`` (gather form), so the loops are race-free;
:func:`forces` works each pair once (from the row that owns it) and writes
both rows, race-free by the slab colouring of :mod:`.colouring`. Pair
quantities use the mean smoothing length

.. math:: h_{ij} = \kappa \, (h_i + h_j) / 2,

with :math:`\kappa` the support scale (the paper's kappa), which keeps
:math:`\nabla_i W_{ij} = -\nabla_j W_{ji}` and hence exact momentum
conservation. Notation: :math:`\mathbf g_{ij} = \nabla_i W(\mathbf x_i -
\mathbf x_j, h_{ij})`.

Energy pairing. The momentum equation (:func:`forces`) is
:math:`\dot{\mathbf v}_i = \sum_j m_j (\sigma_i/\rho_i^2 + \sigma_j/\rho_j^2)
B\mathbf g`; the internal energy rate whose sum with the kinetic energy is
exactly conserved is :math:`\dot e_i = (\sigma_i/\rho_i) : \mathbf L_i` with

.. math:: \mathbf L_i = \frac{1}{\rho_i}\sum_j m_j (\mathbf v_j - \mathbf v_i)
          \otimes \mathbf g_{ij} B_i^T

(Monaghan 1992, eq. 3.4 for the scalar case; Gray, Monaghan & Swift 2001,
eq. 4.8), i.e. quadrature weights :math:`m_j/\rho_i`, not the volumes
:math:`m_j/\rho_j`. Both agree where the density is uniform; where bodies of
different densities meet through the kernel (steel against concrete, a
mesostructure's phases, detonation products against a slab) only the former
keeps the energy balance closed. Its trace gives the summation form of the
continuity equation, :math:`\dot\rho_i = \sum_j m_j (\mathbf v_i - \mathbf
v_j)\cdot\mathbf g_{ij}`.

References
----------
Gray, Monaghan & Swift (2001), SPH elastic dynamics, CMAME 190, 6641-6662.
Randles & Libersky (1996), CMAME 139, 375-408 (gradient renormalisation).
Monaghan (1992), Annu. Rev. Astron. Astrophys. 30, 543-574 (artificial
viscosity, XSPH).
Benz (1989), NATO workshop, Les Arcs (smoothing-length evolution).

The model and its tests: docs/theory.md, "Updated-Lagrangian SPH for solids".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...algebra3 import load3, load9
from ...kernels import kernel_value


@njit(cache=True, error_model="numpy", parallel=True)
def stress_terms(sig, rho, B, P):
    r"""``P_i = sigma_i B_i / rho_i^2`` (N, 3, 3) [Pa m^6/kg^2], the particle's
    term of the momentum sum of :func:`forces`, once per particle and step
    (``B`` (N, 3, 3) the correction matrices of :func:`.gradient.velocity_gradient`,
    the identity without correction; ``sig`` (N, 3, 3) [Pa], ``rho`` (N,)
    [kg/m^3])."""
    for i in prange(sig.shape[0]):
        r2 = 1.0 / (rho[i] * rho[i])
        for a in range(3):
            s0 = sig[i, a, 0] * r2
            s1 = sig[i, a, 1] * r2
            s2 = sig[i, a, 2] * r2
            for b in range(3):
                P[i, a, b] = s0 * B[i, 0, b] + s1 * B[i, 1, b] + s2 * B[i, 2, b]


@njit(cache=True, error_model="numpy", inline="always")
def _force_row(i, x, v, m, rho, h, c, P, F, offsets, count, idx, three, support_scale,
               alpha, beta, a, dedt_av, signal):
    """Row ``i`` of :func:`forces`: its own pairs within the support (the
    row's first ``count[i]``), their terms added to row ``i`` and written to
    row ``j``."""
    per_particle = alpha.shape[0] > 1
    want_signal = signal.shape[0] > 0
    p00, p01, p02, p10, p11, p12, p20, p21, p22 = load9(P, i)
    xi0, xi1, xi2 = load3(x, i)
    vi0, vi1, vi2 = load3(v, i)
    hi = h[i]
    ci = c[i]
    rhoi = rho[i]
    mi = m[i]
    alphai = alpha[i] if per_particle else alpha[0]
    betai = beta[i] if per_particle else beta[0]
    a0 = a1 = a2 = 0.0
    heat = 0.0
    sig_max = 0.0
    for k in range(offsets[i], offsets[i] + count[i]):
        j = idx[k]
        f = F[k]
        mj = m[j]
        if f == 0.0 or (mj == 0.0 and mi == 0.0):  # taken out by a coupling; no mass
            continue
        d0 = xi0 - x[j, 0]
        d1 = xi1 - x[j, 1]
        w0 = vi0 - v[j, 0]
        w1 = vi1 - v[j, 1]
        if three:
            d2 = xi2 - x[j, 2]
            w2 = vi2 - v[j, 2]
        else:
            d2 = 0.0
            w2 = 0.0
        g0 = f * d0
        g1 = f * d1
        g2 = f * d2
        f0 = (p00 + P[j, 0, 0]) * g0 + (p01 + P[j, 0, 1]) * g1 + (p02 + P[j, 0, 2]) * g2
        f1 = (p10 + P[j, 1, 0]) * g0 + (p11 + P[j, 1, 1]) * g1 + (p12 + P[j, 1, 2]) * g2
        f2 = 0.0
        if three:
            f2 = ((p20 + P[j, 2, 0]) * g0 + (p21 + P[j, 2, 1]) * g1
                  + (p22 + P[j, 2, 2]) * g2)
        # artificial viscosity, approaching pairs only
        vx = w0 * d0 + w1 * d1 + w2 * d2
        q = 0.0
        if vx < 0.0:
            hij = support_scale * 0.5 * (hi + h[j])
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            mu = hij * vx / (r2 + 0.01 * hij * hij)
            if per_particle:
                aij = 0.5 * (alphai + alpha[j]) * 0.5 * (ci + c[j])
                bij = 0.5 * (betai + beta[j])
            else:
                aij = alphai * 0.5 * (ci + c[j])
                bij = betai
            pi_ij = (-aij * mu + bij * mu * mu) / (0.5 * (rhoi + rho[j]))
            if want_signal:
                s_ij = aij - bij * mu  # mu < 0
                if mj != 0.0 and s_ij > sig_max:
                    sig_max = s_ij
                if mi != 0.0 and s_ij > signal[j]:
                    signal[j] = s_ij
            f0 -= pi_ij * g0
            f1 -= pi_ij * g1
            f2 -= pi_ij * g2
            q = 0.5 * pi_ij * (w0 * g0 + w1 * g1 + w2 * g2)
        a0 += mj * f0
        a1 += mj * f1
        a2 += mj * f2
        heat += mj * q
        a[j, 0] -= mi * f0
        a[j, 1] -= mi * f1
        a[j, 2] -= mi * f2
        dedt_av[j] += mi * q
    a[i, 0] += a0
    a[i, 1] += a1
    a[i, 2] += a2
    dedt_av[i] += heat
    if want_signal and sig_max > signal[i]:
        signal[i] = sig_max


@njit(cache=True, error_model="numpy", parallel=True)
def forces(x, v, m, rho, h, c, P, F, offsets, count, idx, order, start, dim, support_scale,
           alpha, beta, a, dedt_av, signal):
    r"""Acceleration from the stress divergence and Monaghan artificial viscosity.

    Symmetric (momentum-conserving) form of Gray, Monaghan & Swift (2001),
    extended with the correction matrices :math:`B` so that linear momentum
    stays exactly conserved (pair forces are antisymmetric):

    .. math::
        \dot{\mathbf v}_i = \sum_j m_j \Big(
            \frac{\sigma_i}{\rho_i^2} B_i \mathbf g_{ij}
          + \frac{\sigma_j}{\rho_j^2} B_j \mathbf g_{ij}
          - \Pi_{ij} \mathbf g_{ij} \Big),

    .. math::
        \Pi_{ij} = \frac{-\bar\alpha_{ij} \bar c_{ij} \mu_{ij}
                         + \bar\beta_{ij} \mu_{ij}^2}{\bar\rho_{ij}}, \quad
        \mu_{ij} = \frac{h_{ij} \mathbf v_{ij}\cdot\mathbf x_{ij}}
                        {r_{ij}^2 + 0.01 h_{ij}^2}
        \ \text{if}\ \mathbf v_{ij}\cdot\mathbf x_{ij} < 0,\ \text{else } 0,

    (Monaghan 1992), with the pair's coefficients the means of the two
    particles' (each material may have its own, :mod:`sphdyn.parts.sph.part`).
    The viscous heating rate
    :math:`\dot e_i^{av} = \tfrac12 \sum_j m_j \Pi_{ij}\, \mathbf v_{ij}\cdot
    \mathbf g_{ij}` (>= 0) is written to ``dedt_av``, and the largest
    viscous signal speed of an approaching pair,
    :math:`\max_j (\bar\alpha_{ij}\bar c_{ij} + \bar\beta_{ij}|\mu_{ij}|)`
    (0 without one), to ``signal``: Monaghan's (1992, sec. 10) time-step
    condition :math:`h / (c + 1.2(\alpha c + \beta \max_j \mu_{ij}))`
    uses it (:func:`sphdyn.integrate.cfl_time_step`). Zero-mass neighbours
    contribute nothing; a zero-mass particle still gets an acceleration (it
    moves as an interpolation point).

    Each pair is worked once, by the row of lower rank (the row's own
    pairs, at its head: :func:`~sphdyn.parts.sph.colouring.own_pairs_first`,
    then :func:`.gradient.velocity_gradient`), and its terms written to both rows
    (:math:`\mathbf g_{ji} = -\mathbf g_{ij}`, :math:`\Pi_{ji} = \Pi_{ij}`:
    the pair's acceleration terms are :math:`m_j \mathbf f_{ij}` on i and
    :math:`-m_i \mathbf f_{ij}` on j, its heating and signal speed the same
    on both), the slabs of
    :func:`~sphdyn.parts.sph.colouring.pair_colouring` taken in two colours
    so that no two threads write one row: half the arithmetic of a gather
    over both rows (BENCHMARKS.md, 2026-11-28). The order of each row's
    additions is fixed by the colouring, so the results are the same for
    any number of threads.

    Parameters
    ----------
    x, v : (N, 3) positions [m], velocities [m/s].
    m, rho, h, c : (N,) mass [kg], density [kg/m^3], smoothing length [m],
        wave speed [m/s].
    P : (N, 3, 3) ``sigma B / rho^2`` from :func:`stress_terms` (Cauchy,
        tension +), so the pair term is :math:`(P_i + P_j)\,\mathbf g_{ij}`.
    F : (nnz,) pair gradient factors from :func:`.gradient.velocity_gradient`.
    offsets, count, idx : the neighbour list and the row's own pairs within
        the support at the head of each row (:func:`.gradient.velocity_gradient`); only
        those are visited.
    order, start : the list's slab colouring
        (:class:`~sphdyn.parts.sph.colouring.ListColouring`), whose ranks
        chose the own pairs.
    alpha, beta : (N,) artificial-viscosity coefficients of each particle
        [-], or (1,) the one value of all (no per-pair means to form).
    a : (N, 3) out, acceleration [m/s^2].
    dedt_av : (N,) out, viscous heating rate [W/kg].
    signal : (N,) out, viscous signal speed [m/s], or (0,): not wanted (no
        fluid particles; the pass then skips it).
    """
    n = x.shape[0]
    three = dim == 3
    for i in prange(n):
        a[i, 0] = 0.0
        a[i, 1] = 0.0
        a[i, 2] = 0.0
        dedt_av[i] = 0.0
    for i in prange(signal.shape[0]):
        signal[i] = 0.0
    slabs = start.shape[0] - 1
    for colour in range(2):
        for t in prange((slabs - colour + 1) // 2):
            s = colour + 2 * t
            for r in range(start[s], start[s + 1]):
                _force_row(order[r], x, v, m, rho, h, c, P, F, offsets, count, idx, three,
                           support_scale, alpha, beta, a, dedt_av, signal)


@njit(cache=True, error_model="numpy", parallel=True)
def xsph_velocity(x, v, m, rho, h, offsets, idx, kid, sigma, dim, support_scale, eps,
                  vs):
    r"""XSPH smoothed transport velocity (Monaghan 1992, eq. 4.3).

    .. math:: \hat{\mathbf v}_i = \mathbf v_i + \varepsilon \sum_j
              \frac{m_j}{\bar\rho_{ij}} (\mathbf v_j - \mathbf v_i) W_{ij}

    Positions are advanced with :math:`\hat{\mathbf v}`; momentum uses
    :math:`\mathbf v`. ``vs`` (N, 3) out [m/s].
    """
    n = x.shape[0]
    for i in prange(n):
        s0 = s1 = s2 = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            if m[j] == 0.0:
                continue
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            hij = support_scale * 0.5 * (h[i] + h[j])
            w = kernel_value(kid, sigma, dim, r, hij) * m[j] / (0.5 * (rho[i] + rho[j]))
            s0 += w * (v[j, 0] - v[i, 0])
            s1 += w * (v[j, 1] - v[i, 1])
            s2 += w * (v[j, 2] - v[i, 2])
        vs[i, 0] = v[i, 0] + eps * s0
        vs[i, 1] = v[i, 1] + eps * s1
        vs[i, 2] = v[i, 2] + eps * s2


@njit(cache=True, error_model="numpy", parallel=True)
def update_density_and_h(L, dt, dim, benz, h0, hmin_factor, hmax_factor, rho, h, rho0,
                         mat, limits):
    r"""Continuity equation and Benz smoothing-length evolution.

    .. math::
        \frac{d\rho_i}{dt} = -\rho_i \operatorname{tr} L_i, \qquad
        \frac{dh_i}{dt} = \frac{h_i}{d} \operatorname{tr} L_i
        \quad\text{(Benz 1989; paper eq. 7)}

    integrated exactly for constant :math:`\operatorname{tr} L` over the step
    (exponential update, keeps both positive), the density then kept within
    ``limits[mat_i] * rho0_i`` (Autodyn's SPH minimum and maximum density
    factors). The rate :math:`\dot\rho_i = -\rho_i \operatorname{tr} L_i =
    \sum_j m_j (\mathbf v_i - \mathbf v_j)\cdot\mathbf g_{ij}` does not scale
    with :math:`\rho_i`: a sparse particle that keeps expanding (the debris of
    eroded elements) falls to nearly no density, and a compression after that
    multiplies it by :math:`e^{\Delta t \dot\rho_i/\rho_i}`, which overflows
    (1e-9 then 9e38 kg/m^3 in the 400 m/s penetration, docs/examples.md).
    With ``benz`` False ``h`` is unchanged; otherwise it is clipped to
    ``[hmin_factor, hmax_factor] * h0``. ``rho``, ``h`` (N,) updated in place;
    ``rho0`` (N,) initial density [kg/m^3], ``mat`` (N,) material index,
    ``limits`` (n_materials, 2) the (min, max) factors, or (0, 2) for none.
    """
    n = rho.shape[0]
    inv_d = 1.0 / dim
    limited = limits.shape[0] > 0
    for i in prange(n):
        div = L[i, 0, 0] + L[i, 1, 1] + L[i, 2, 2]
        r = rho[i] * np.exp(-dt * div)
        if limited:
            lo = limits[mat[i], 0] * rho0[i]
            hi = limits[mat[i], 1] * rho0[i]
            if r < lo:
                r = lo
            elif r > hi:
                r = hi
        rho[i] = r
        if benz:
            hn = h[i] * np.exp(dt * div * inv_d)
            lo = hmin_factor * h0[i]
            hi = hmax_factor * h0[i]
            if hn < lo:
                hn = lo
            elif hn > hi:
                hn = hi
            h[i] = hn
