r"""The one-point hex8 passes, vectorised: :data:`.lane_layout.LANES` elements side by side.

The same equations, in the same order of operations, as the element-by-element
passes :func:`.solid.uniform_strain_rate` and :func:`.solid.uniform_forces`
(module docstring of :mod:`.solid`: Flanagan & Belytschko 1981, the
mid-step velocity gradient, bulk viscosity, viscous and stiffness hourglass
control, the element step), so both give the same bits (a test compares
them). What differs is the layout: each block of
:data:`.solid.ELEMENT_BLOCK` elements is worked in groups of ``LANES``:

1. a scalar loop gathers the group's node coordinates and velocities (and
   the element fields the pass reads) into the rows of a flat scratch
   (:mod:`.lane_layout`);
2. loops over the lanes, with every node and component unrolled, compute the
   volume derivatives (:func:`.hex_gradient.hex_volume_gradient_lanes`), the
   velocity gradient, the hourglass resultants and the nodal forces: the
   compiler turns them into SIMD loops (8 doubles per AVX-512 instruction),
   which the element-by-element code, a chain of dependent scalar
   reductions, cannot use;
3. a scalar loop writes the group's results to the element arrays (inactive
   elements: no rate, zero forces, an infinite step).

A group at the end of a block is padded with copies of its last element;
their results are not written.

The model and its tests: docs/theory.md, "Solid finite elements".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...geometry.shapes import hourglass_vectors
from .hex_gradient import hex_volume_gradient_lanes
from .lane_layout import (C_, COEF_, DKK_, DT_, ELL_, F_, FACE_, G_, GM_, HEAT_, HG_, INV_, INVV_,
                          L_, LANES, LB_, M_, MSH_, MX_, OV_, POWER_, PX_, Q_, QA_, RG_, RHO_, ROW_,
                          ROWS, SIG_, TR_, VN_, VOL_, X_)
from .solid import block_count, block_span, bulk_viscosity, element_step, length_from_gradient
from .hourglass import (HG_VISCOUS, hourglass_coefficient, hourglass_face, hourglass_rates,
                        overlap_from_moments)

#: hourglass base vectors (4, 8) of the hex8, a compile-time constant
GAMMA = hourglass_vectors(3)


def lane_scratch(n: int) -> np.ndarray:
    """Scratch (B, ROWS * LANES) of the lane passes: one row per block of
    :func:`.solid.block_count` (``n`` elements), made once by the part."""
    return np.zeros((block_count(n), ROWS * LANES))


@njit(cache=True, error_model="numpy")
def gather_nodes(x, v, s, conn, lo, nl, S):
    r"""Rows X_ (coordinates at :math:`\mathbf x - s\mathbf v` relative to node 0, as
    :func:`.solid.local_coordinates`) and VN_ (velocities) of elements ``lo``
    .. ``lo + nl - 1``; lanes beyond ``nl`` repeat the last element."""
    for l in range(LANES):
        e = lo + min(l, nl - 1)
        n0 = conn[e, 0]
        for I in range(8):
            n = conn[e, I]
            for k in range(3):
                S[(X_ + 3 * I + k) * LANES + l] = ((x[n, k] - s * v[n, k])
                                                   - (x[n0, k] - s * v[n0, k]))
                S[(VN_ + 3 * I + k) * LANES + l] = v[n, k]


@njit(cache=True, error_model="numpy")
def velocity_moments(S, row):
    r"""Rows ``row`` .. ``row + 8`` (i, j row-major): :math:`\sum_I v_{iI}\,
    \partial V/\partial x_{jI}` [m^3/s] from rows VN_ and G_ (the velocity
    gradient times V)."""
    for i in range(3):
        for j in range(3):
            for l in range(LANES):
                s = 0.0
                for I in range(8):
                    s += S[(VN_ + 3 * I + i) * LANES + l] * S[(G_ + 3 * I + j) * LANES + l]
                S[(row + 3 * i + j) * LANES + l] = s


@njit(cache=True, error_model="numpy")
def rate_lanes(S):
    r"""Rows INV_ (1/V, 0 if V <= 0) and L_ (:math:`L_{ij} = \sum_I v_{iI}\,
    \partial V/\partial x_{jI} / V`) from rows VN_, G_, VOL_."""
    velocity_moments(S, L_)
    for l in range(LANES):
        vm = S[VOL_ * LANES + l]
        inv = 1.0 / vm if vm > 0.0 else 0.0
        S[INV_ * LANES + l] = inv
        for r in range(9):
            S[(L_ + r) * LANES + l] *= inv


@njit(cache=True, error_model="numpy", parallel=True)
def hex_strain_rate(x, v, conn, active, m_el, dt, L, rho, work):
    r"""Velocity gradient ``L`` (E, 3, 3) [1/s] and density ``rho = m_el / V`` (E,)
    of one-point hex8 elements on the mid-step geometry
    :math:`\mathbf x - \tfrac{\Delta t}2\mathbf v` (:func:`.solid.uniform_strain_rate`,
    lane by lane). ``work``: :func:`lane_scratch`."""
    ne = conn.shape[0]
    for b in prange(block_count(ne)):
        S = work[b]
        blo, bhi = block_span(b, ne)
        for lo in range(blo, bhi, LANES):
            nl = min(bhi - lo, LANES)
            gather_nodes(x, v, 0.5 * dt, conn, lo, nl, S)
            hex_volume_gradient_lanes(S)
            rate_lanes(S)
            for l in range(nl):
                e = lo + l
                if active[e] == 0:
                    continue
                rho[e] = m_el[e] * S[INV_ * LANES + l]
                for i in range(3):
                    for j in range(3):
                        L[e, i, j] = S[(L_ + 3 * i + j) * LANES + l]


@njit(cache=True, error_model="numpy")
def gather_fields(sig, L, rho, c, hg, lo, nl, stiffness, m_el, S):
    """Rows SIG_, DKK_, RHO_, C_, MSH_ (each node's share of the element mass
    ``m_el``) and FACE_ (viscous form) or HG_ (stiffness form) of elements
    ``lo`` .. ``lo + nl - 1``, padded as :func:`gather_nodes`."""
    for l in range(LANES):
        e = lo + min(l, nl - 1)
        S[MSH_ * LANES + l] = m_el[e] / 8
        for i in range(3):
            for j in range(3):
                S[(SIG_ + 3 * i + j) * LANES + l] = sig[e, i, j]
        S[DKK_ * LANES + l] = L[e, 0, 0] + L[e, 1, 1] + L[e, 2, 2]
        S[RHO_ * LANES + l] = rho[e]
        S[C_ * LANES + l] = c[e]
        if not stiffness:  # V^(2/3) of the viscous form (a libm call: only if used)
            S[FACE_ * LANES + l] = hourglass_face(S[VOL_ * LANES + l], 3)
        else:
            for a in range(4):
                for k in range(3):
                    S[(HG_ + 3 * a + k) * LANES + l] = hg[e, a, k]


@njit(cache=True, error_model="numpy")
def overlap_lanes(S):
    """Row OV_: :func:`.solid.hourglass_overlap` of every lane from rows X_, G_,
    VOL_ (the same operations in the same order, lane by lane; rows MX_,
    PX_ and RG_ hold the mean coordinates and the moments on the way)."""
    for r in range(15):
        for l in range(LANES):
            S[(MX_ + r) * LANES + l] = 0.0
    for I in range(8):
        for k in range(3):
            for l in range(LANES):
                S[(MX_ + k) * LANES + l] += S[(X_ + 3 * I + k) * LANES + l]
    for k in range(3):
        for l in range(LANES):
            S[(MX_ + k) * LANES + l] /= 8
    for I in range(8):
        for l in range(LANES):
            y0 = S[(X_ + 3 * I) * LANES + l] - S[MX_ * LANES + l]
            y1 = S[(X_ + 3 * I + 1) * LANES + l] - S[(MX_ + 1) * LANES + l]
            y2 = S[(X_ + 3 * I + 2) * LANES + l] - S[(MX_ + 2) * LANES + l]
            g0 = S[(G_ + 3 * I) * LANES + l]
            g1 = S[(G_ + 3 * I + 1) * LANES + l]
            g2 = S[(G_ + 3 * I + 2) * LANES + l]
            S[PX_ * LANES + l] += y0 * y0
            S[(PX_ + 1) * LANES + l] += y0 * y1
            S[(PX_ + 2) * LANES + l] += y0 * y2
            S[(PX_ + 3) * LANES + l] += y1 * y1
            S[(PX_ + 4) * LANES + l] += y1 * y2
            S[(PX_ + 5) * LANES + l] += y2 * y2
            S[RG_ * LANES + l] += g0 * g0
            S[(RG_ + 1) * LANES + l] += g0 * g1
            S[(RG_ + 2) * LANES + l] += g0 * g2
            S[(RG_ + 3) * LANES + l] += g1 * g1
            S[(RG_ + 4) * LANES + l] += g1 * g2
            S[(RG_ + 5) * LANES + l] += g2 * g2
    for l in range(LANES):
        S[OV_ * LANES + l] = overlap_from_moments(
            S[PX_ * LANES + l], S[(PX_ + 1) * LANES + l], S[(PX_ + 2) * LANES + l],
            S[(PX_ + 3) * LANES + l], S[(PX_ + 4) * LANES + l], S[(PX_ + 5) * LANES + l],
            S[RG_ * LANES + l], S[(RG_ + 1) * LANES + l], S[(RG_ + 2) * LANES + l],
            S[(RG_ + 3) * LANES + l], S[(RG_ + 4) * LANES + l], S[(RG_ + 5) * LANES + l],
            S[VOL_ * LANES + l], 3)


@njit(cache=True, error_model="numpy")
def force_lanes(S, hg_form, qh, q1, q2, dt):
    r"""Element step (row DT_), bulk viscosity (Q_, HEAT_), hourglass power
    (POWER_; new stiffness-form forces into HG_) and nodal forces (F_) from
    the gathered rows: :func:`.solid.uniform_forces` and
    :func:`.solid.hourglass_resultants` term by term.

    Written as loops over the lanes inside loops over the modes and nodes
    (each lane loop small enough for the compiler to unroll what is inside
    it and vectorise it); the rows SIG_ end holding :math:`\sigma - q\mathbf 1
    - M`.
    """
    for l in range(LANES):
        V = S[VOL_ * LANES + l]
        rho = S[RHO_ * LANES + l]
        c = S[C_ * LANES + l]
        dkk = S[DKK_ * LANES + l]
        S[TR_ * LANES + l] = 0.0
        bb = 0.0
        for I in range(8):
            g0 = S[(G_ + 3 * I) * LANES + l]
            g1 = S[(G_ + 3 * I + 1) * LANES + l]
            g2 = S[(G_ + 3 * I + 2) * LANES + l]
            bb += g0 * g0 + g1 * g1 + g2 * g2
        ell = length_from_gradient(V, 8, bb)
        S[ELL_ * LANES + l] = ell
        q = bulk_viscosity(rho, c, ell, dkk, q1, q2)
        S[Q_ * LANES + l] = q
        S[HEAT_ * LANES + l] = -dt * q * dkk / rho if q > 0.0 and rho > 0.0 else 0.0
        hourglass = qh > 0.0 and V > 0.0
        coef = hourglass_coefficient(hg_form, qh, rho, c, S[FACE_ * LANES + l], bb, V, 3)
        S[COEF_ * LANES + l] = coef if hourglass else 0.0
        S[INVV_ * LANES + l] = 1.0 / V if hourglass else 0.0
        S[POWER_ * LANES + l] = 0.0
    # hourglass_resultants: Lb = sum_I v_I (x) g_I (no 1/V), h_a = sum_J Gamma_aJ x_J / V
    velocity_moments(S, LB_)
    for r in range(9):
        for l in range(LANES):
            S[(M_ + r) * LANES + l] = 0.0
    for a in range(4):
        for l in range(LANES):
            h0 = h1 = h2 = 0.0
            w0 = w1 = w2 = 0.0
            for J in range(8):
                G = GAMMA[a, J]
                h0 += G * S[(X_ + 3 * J) * LANES + l]
                h1 += G * S[(X_ + 3 * J + 1) * LANES + l]
                h2 += G * S[(X_ + 3 * J + 2) * LANES + l]
                w0 += G * S[(VN_ + 3 * J) * LANES + l]
                w1 += G * S[(VN_ + 3 * J + 1) * LANES + l]
                w2 += G * S[(VN_ + 3 * J + 2) * LANES + l]
            inv_v = S[INVV_ * LANES + l]
            coef = S[COEF_ * LANES + l]
            h0 *= inv_v
            h1 *= inv_v
            h2 *= inv_v
            tr = S[TR_ * LANES + l]
            for I in range(8):  # the shape vectors and their Gram trace (the step)
                gm = GAMMA[a, I] - (
                    h0 * S[(G_ + 3 * I) * LANES + l] + h1 * S[(G_ + 3 * I + 1) * LANES + l]
                    + h2 * S[(G_ + 3 * I + 2) * LANES + l])
                S[(GM_ + 8 * a + I) * LANES + l] = gm
                tr += gm * gm
            S[TR_ * LANES + l] = tr
            qd0 = w0 - (S[LB_ * LANES + l] * h0 + S[(LB_ + 1) * LANES + l] * h1
                        + S[(LB_ + 2) * LANES + l] * h2)
            qd1 = w1 - (S[(LB_ + 3) * LANES + l] * h0 + S[(LB_ + 4) * LANES + l] * h1
                        + S[(LB_ + 5) * LANES + l] * h2)
            qd2 = w2 - (S[(LB_ + 6) * LANES + l] * h0 + S[(LB_ + 7) * LANES + l] * h1
                        + S[(LB_ + 8) * LANES + l] * h2)
            if hg_form == HG_VISCOUS:
                Q0 = coef * qd0
                Q1 = coef * qd1
                Q2 = coef * qd2
            else:
                Q0 = S[(HG_ + 3 * a) * LANES + l] + dt * coef * qd0
                Q1 = S[(HG_ + 3 * a + 1) * LANES + l] + dt * coef * qd1
                Q2 = S[(HG_ + 3 * a + 2) * LANES + l] + dt * coef * qd2
                S[(HG_ + 3 * a) * LANES + l] = Q0
                S[(HG_ + 3 * a + 1) * LANES + l] = Q1
                S[(HG_ + 3 * a + 2) * LANES + l] = Q2
            on = inv_v != 0.0  # hourglass control acts (the forces' Q term below)
            S[(QA_ + 3 * a) * LANES + l] = Q0 if on else 0.0
            S[(QA_ + 3 * a + 1) * LANES + l] = Q1 if on else 0.0
            S[(QA_ + 3 * a + 2) * LANES + l] = Q2 if on else 0.0
            S[POWER_ * LANES + l] += Q0 * qd0 + Q1 * qd1 + Q2 * qd2
            S[M_ * LANES + l] += Q0 * h0
            S[(M_ + 1) * LANES + l] += Q0 * h1
            S[(M_ + 2) * LANES + l] += Q0 * h2
            S[(M_ + 3) * LANES + l] += Q1 * h0
            S[(M_ + 4) * LANES + l] += Q1 * h1
            S[(M_ + 5) * LANES + l] += Q1 * h2
            S[(M_ + 6) * LANES + l] += Q2 * h0
            S[(M_ + 7) * LANES + l] += Q2 * h1
            S[(M_ + 8) * LANES + l] += Q2 * h2
    # .solid.hourglass_bound: the smaller of the trace and Gershgorin's
    # max_a sum_b |sum_I gamma_aI gamma_bI|, then the element step with the
    # hourglass control's terms (.solid.hourglass_rates, .solid.element_step)
    for l in range(LANES):
        S[ROW_ * LANES + l] = 0.0  # the largest row sum so far
    for a in range(4 if qh > 0.0 else 0):
        for l in range(LANES):
            row = 0.0
            for b in range(4):
                s = 0.0
                for I in range(8):
                    s += S[(GM_ + 8 * a + I) * LANES + l] * S[(GM_ + 8 * b + I) * LANES + l]
                row += abs(s)
            S[ROW_ * LANES + l] = max(S[ROW_ * LANES + l], row)
    if qh > 0.0:
        overlap_lanes(S)
    for l in range(LANES):
        lam = min(S[TR_ * LANES + l], S[ROW_ * LANES + l])
        a_h, w2_h = hourglass_rates(lam, S[COEF_ * LANES + l], S[MSH_ * LANES + l], hg_form)
        ov = S[OV_ * LANES + l] if S[COEF_ * LANES + l] > 0.0 else 0.0
        S[DT_ * LANES + l] = element_step(S[ELL_ * LANES + l], S[C_ * LANES + l],
                                          S[DKK_ * LANES + l], q1, q2, a_h, w2_h, ov)
    # f_iI = -(sigma_ij - q delta_ij - M_ij / V) dV/dx_jI - sum_a Q_ai Gamma_aI
    for i in range(3):
        for j in range(3):
            for l in range(LANES):
                r = S[(SIG_ + 3 * i + j) * LANES + l]
                if i == j:
                    r -= S[Q_ * LANES + l]
                S[(SIG_ + 3 * i + j) * LANES + l] = r - S[(M_ + 3 * i + j) * LANES + l]
    for I in range(8):
        for i in range(3):
            for l in range(LANES):
                f = (S[(SIG_ + 3 * i) * LANES + l] * S[(G_ + 3 * I) * LANES + l]
                     + S[(SIG_ + 3 * i + 1) * LANES + l] * S[(G_ + 3 * I + 1) * LANES + l]
                     + S[(SIG_ + 3 * i + 2) * LANES + l] * S[(G_ + 3 * I + 2) * LANES + l])
                for a in range(4):  # zero rows QA_ without hourglass control
                    f += S[(QA_ + 3 * a + i) * LANES + l] * GAMMA[a, I]
                S[(F_ + 3 * I + i) * LANES + l] = -f


@njit(cache=True, error_model="numpy", parallel=True)
def hex_forces(x, v, conn, active, sig, L, rho, c, e_spec, e_av, hg_form, qh, hg, e_hg,
               q1, q2, dt, vol, dt_el, fe, work, m_el):
    r"""Nodal forces ``fe`` (E, 8, 3) [N] of one-point hex8 elements, lane by lane:
    :func:`.solid.uniform_forces` (same arguments and equations: the geometry
    at :math:`n+1` with ``vol`` and ``dt_el`` written on the way, bulk
    viscosity heating ``e_spec`` and ``e_av``, hourglass forces with their work
    in ``e_hg`` and the stiffness form's ``hg`` (E, 4, 3) updated; the
    element step with its hourglass control's terms,
    :func:`.solid.hourglass_rates` with the element masses ``m_el`` (E,) [kg]).
    ``work``: :func:`lane_scratch`."""
    ne = conn.shape[0]
    stiffness = hg_form != HG_VISCOUS
    for b in prange(block_count(ne)):
        S = work[b]
        blo, bhi = block_span(b, ne)
        for lo in range(blo, bhi, LANES):
            nl = min(bhi - lo, LANES)
            gather_nodes(x, v, 0.0, conn, lo, nl, S)
            hex_volume_gradient_lanes(S)
            gather_fields(sig, L, rho, c, hg, lo, nl, stiffness, m_el, S)
            force_lanes(S, hg_form, qh, q1, q2, dt)
            for l in range(nl):
                e = lo + l
                if active[e] == 0:
                    for I in range(8):
                        for k in range(3):
                            fe[e, I, k] = 0.0
                    dt_el[e] = np.inf
                    continue
                V = S[VOL_ * LANES + l]
                vol[e] = V
                dt_el[e] = S[DT_ * LANES + l]
                if S[Q_ * LANES + l] > 0.0 and rho[e] > 0.0:
                    heat = S[HEAT_ * LANES + l]
                    e_spec[e] += heat
                    e_av[e] += heat
                if qh > 0.0 and V > 0.0:
                    e_hg[e] += dt * S[POWER_ * LANES + l]
                    if stiffness:
                        for a in range(4):
                            for k in range(3):
                                hg[e, a, k] = S[(HG_ + 3 * a + k) * LANES + l]
                for I in range(8):
                    for k in range(3):
                        fe[e, I, k] = S[(F_ + 3 * I + k) * LANES + l]
