r"""Numba kernels of the solid elements: hex8 (3D) and quad4 (2D plane strain).

One code path for both (``dim`` 3 or 2, ``nen`` 8 or 4). Element loops run in
``prange`` and write only their own element's rows (the element nodal forces
``fe`` (E, nen, 3)); :func:`.gather.gather_loads` then sums them per node
from the node-to-element list, so no two threads write the same memory.

One-point elements take two passes a step, each over blocks of
:data:`ELEMENT_BLOCK` elements with a small scratch per block (node
coordinates, velocities, volume derivatives): :func:`uniform_strain_rate`
(mid-step geometry, velocity gradient, density), the material update, then
:func:`uniform_forces` (end-of-step geometry, volume, element step, forces).
Nothing per element is stored between the passes but the point fields, so a
hex8 costs about 1.2 kB with its node and point (BENCHMARKS.md). The part
runs the one-point hex8 through :mod:`.hex_lanes`, the same equations in the
same order for 16 elements side by side (SIMD; the same bits, about 2x
faster); the element-by-element passes here serve the quad4 and are the
reference the lane passes are tested against.

**Kinematics.** Velocities are at :math:`n+\tfrac12`, positions at
:math:`n+1`. The velocity gradient is evaluated on the mid-step geometry
:math:`\mathbf x^{n+1/2} = \mathbf x^{n+1} - \tfrac{\Delta t}2 \mathbf v^{n+1/2}`:
for a rigid rotation the chord velocities then have an exactly skew gradient
(the Cayley transform of the rotation), so a rotating element strains by
zero (Belytschko, Liu & Moran 2000, sec. 6.2.2, mid-step configuration).

**One-point integration** (Flanagan & Belytschko 1981, IJNME 17, 679-706):
with the uniform gradient :math:`b_{iI} = \frac1V \partial V/\partial x_{iI}`
(:mod:`sphdyn.geometry.shapes`),

.. math:: L_{ij} = \sum_I v_{iI}\, b_{jI}, \qquad
          f^{int}_{iI} = -V (\sigma_{ij} - q\,\delta_{ij})\, b_{jI},

exact for linear velocity fields on any hexahedron (patch test).

**Hourglass control** and its share of the stable step: :mod:`.hourglass`.

**Bulk viscosity** (von Neumann-Richtmyer; LS-DYNA defaults Q1 = 1.5,
Q2 = 0.06): for :math:`\dot\varepsilon_{kk} < 0`,
:math:`q = \rho\, \ell\, (Q_1 \ell\, \dot\varepsilon_{kk}^2 - Q_2\, c\,
\dot\varepsilon_{kk})`, a pressure added to the stress in the force; its
power :math:`-q\dot\varepsilon_{kk}/\rho` heats the point (``e``, ``e_av``).

**Selective-reduced integration** (Hughes 1980, B-bar, IJNME 15, 1413):
2^d Gauss points; at each the deviatoric part of L is the point's own, the
volumetric part that of the uniform gradient, and the forces are the
virtual work of the same :math:`\bar B`:
:math:`f_{iI} = -\sum_g w_g J_g [\sigma_{ij} B_{jI} + \tfrac1d
\sigma_{kk} (\bar b_{iI} - B_{iI})]` (d = 3; in plane strain d = 2 for the
in-plane trace).
Each point's work is booked with the volume its Gauss point stands for,
:math:`\Delta(m_g e_g) = \Delta t\, \bar\sigma_g:\bar{\mathbf D}_g\,
J_g` (:math:`J_g` on the mid-step geometry, :func:`weigh_point_work`), the
weight of the same point in the forces: the material books
:math:`\Delta t\,\bar\sigma:\bar{\mathbf D}/\rho` per unit mass with the
element's density :math:`\rho = m_e/V`, which is the point's share
:math:`V/2^d` and so its work only in an element whose points have equal
volumes (a parallelepiped); in a distorted one the forces' work and the
booked energy differ by :math:`\sum_g (J_g - V/2^d)\,\bar\sigma_g:
\bar{\mathbf D}_g`, energy made from nothing (docs/theory.md).

**Stable step** (Flanagan & Belytschko 1981, eq. 64): the largest
eigenvalue of the uniform-strain element with lumped mass is bounded by
:math:`\omega^2 \le n_{en} c^2 \sum_{iI} b_{iI}^2 / 4`, so
:math:`\Delta t = \ell / (Q + \sqrt{Q^2 + c^2})`,
:math:`\ell = 2 / \sqrt{n_{en} \sum b^2}`,
:math:`Q = Q_2 c + Q_1 \ell |\dot\varepsilon_{kk}|` in compression (LS-DYNA's
form with the bulk viscosity). For a cube of side a: :math:`\ell = a/\sqrt3`
(the odd-even dilatational mode of a cube mesh has :math:`\omega^2 = 12K/\rho
a^2`, which this bound covers for any Poisson ratio).
"""

from __future__ import annotations


import numpy as np
from numba import njit, prange

from ...simd import sqrt
from .hex_gradient import hex_volume_gradient
from .hourglass import element_hourglass_rates, hourglass_resultants


@njit(cache=True, error_model="numpy")
def local_coordinates(x, v, s, conn, e, xl):
    """Node coordinates of element ``e`` at ``x - s v``, relative to its first node.

    ``x``, ``v`` (N, 3); ``conn`` (E, nen); ``xl`` (nen, 3) out [m]. Relative
    coordinates keep the volume's cubic form free of cancellation far from
    the origin.
    """
    n0 = conn[e, 0]
    for I in range(conn.shape[1]):
        n = conn[e, I]
        for k in range(3):
            xl[I, k] = (x[n, k] - s * v[n, k]) - (x[n0, k] - s * v[n0, k])


@njit(cache=True, error_model="numpy")
def element_nodes(x, v, s, conn, e, xl, vl):
    """:func:`local_coordinates` of element ``e`` into ``xl`` and its node
    velocities into ``vl`` (nen, 3) [m/s], read once for the element's passes."""
    local_coordinates(x, v, s, conn, e, xl)
    for I in range(conn.shape[1]):
        n = conn[e, I]
        for k in range(3):
            vl[I, k] = v[n, k]


@njit(cache=True, error_model="numpy")
def volume_gradient(xl, dim, tab, g):
    r"""Volume derivatives :math:`\partial V/\partial x_{iI}` (nen, 3) into ``g``; returns V.

    ``xl`` (nen, 3) node coordinates (rows beyond nen are ignored); ``tab``
    the table of :func:`sphdyn.geometry.shapes.volume_table`. 3D:
    :math:`\partial V/\partial x_I = \tfrac1{12}\sum_J y_J (z_{P1} + z_{P2} -
    z_{M1} - z_{M2})` (cyclic), unrolled in :mod:`.hex_gradient` (generated
    from the table by ``tools/gen_hex_gradient.py``), :math:`V = \tfrac13\sum_I \mathbf x_I
    \cdot \partial V/\partial \mathbf x_I`; 2D: :math:`\partial A/\partial x_I =
    \tfrac12 \sum s\, y_J`, :math:`\partial A/\partial y_I = -\tfrac12\sum s\, x_J`,
    :math:`A = \tfrac12 \sum_I \mathbf x_I\cdot\partial A/\partial\mathbf x_I`
    (area per unit depth; ``g[:, 2] = 0``).
    """
    if dim == 3:
        return hex_volume_gradient(xl, g)  # the table's expressions, unrolled
    nen = tab.shape[0]
    vol = 0.0
    for I in range(nen):
        sx = 0.0
        sy = 0.0
        for k in range(tab.shape[1]):
            J = tab[I, k, 0]
            sg = tab[I, k, 1]
            sx += sg * xl[J, 1]
            sy -= sg * xl[J, 0]
        g[I, 0] = 0.5 * sx
        g[I, 1] = 0.5 * sy
        g[I, 2] = 0.0
        vol += xl[I, 0] * g[I, 0] + xl[I, 1] * g[I, 1]
    return 0.5 * vol


@njit(cache=True, error_model="numpy")
def char_length(g, vol):
    r"""Characteristic length :math:`\ell = 2/\sqrt{n_{en}\sum b^2}`, :math:`b = g / V` [m]
    (``g`` (nen, 3) the volume derivatives [m^2], ``vol`` [m^3])."""
    s = 0.0
    for I in range(g.shape[0]):
        s += g[I, 0] ** 2 + g[I, 1] ** 2 + g[I, 2] ** 2
    return length_from_gradient(vol, g.shape[0], s)


@njit(cache=True, error_model="numpy")
def length_from_gradient(vol, nen, s):
    r""":math:`\ell = 2 V/\sqrt{n_{en} s}` of :func:`char_length`, from ``s`` =
    :math:`\sum_I |\partial V/\partial\mathbf x_I|^2` [m^4]; 0 for a degenerate
    element (the lane passes sum ``s`` themselves)."""
    if s <= 0.0 or vol <= 0.0:
        return 0.0
    return 2.0 * vol / sqrt(nen * s)


#: elements per block of the one-point loops: a block's thread keeps the
#: element's node coordinates and volume derivatives in its own small scratch
#: (L1-resident), so no per-element geometry is stored between the passes
ELEMENT_BLOCK = 256


@njit(cache=True, error_model="numpy")
def block_count(n):
    """Blocks of :data:`ELEMENT_BLOCK` elements that cover ``n`` elements."""
    return (n + ELEMENT_BLOCK - 1) // ELEMENT_BLOCK


@njit(cache=True, error_model="numpy")
def block_span(b, n):
    """The elements ``lo:hi`` of block ``b`` (of ``n`` elements)."""
    lo = b * ELEMENT_BLOCK
    return lo, min(n, lo + ELEMENT_BLOCK)


def block_scratch(n: int, nen: int, modes: int) -> np.ndarray:
    """Scratch (B, 3 nen + modes + 3, 3) of the one-point passes, one slab per
    block of :func:`block_count` (``n`` elements), made once by the part so that
    a step allocates nothing: node coordinates, velocities and volume
    derivatives (nen rows each), hourglass forces (``modes`` rows), their
    share M (3 rows)."""
    return np.empty((block_count(n), 3 * nen + modes + 3, 3))


@njit(cache=True, error_model="numpy")
def element_step(ell, c, dkk, q1, q2, a_h, w2_h, overlap):
    r"""Stable step of one element [s]: the plain form :math:`\ell/(Q + \sqrt{Q^2 +
    c^2})` with :math:`Q = Q_2 c + Q_1\ell|\dot\varepsilon_{kk}|` in compression,
    and with the hourglass control's damping rate ``a_h`` :math:`A_h` [1/s]
    and stiffness ``w2_h`` :math:`\omega_h^2` [1/s^2] (:func:`hourglass_rates`;
    0 without it) the smaller of two damped-oscillator limits
    :math:`2/(A + \sqrt{A^2+\omega^2})` (module docstring, "Stable step with the
    hourglass control"): the element's own terms with the hourglass terms
    times ``overlap`` :math:`c_\theta` (:func:`hourglass_overlap`) added,
    :math:`Q + c_\theta A_h\ell/2`, :math:`c^2 + c_\theta\omega_h^2\ell^2/4`,
    and the hourglass terms with the element's times :math:`c_\theta` added,
    :math:`A_h\ell/2 + c_\theta Q`, :math:`\omega_h^2\ell^2/4 + c_\theta c^2`.
    At :math:`c_\theta = 0` (an undistorted element) the two limits taken apart,
    at 1 their sum's; the plain form's bits where both terms are 0. ``ell``
    [m], ``c`` [m/s], ``dkk`` the volumetric strain rate [1/s]; the factor
    ``cfl`` is applied by the part."""
    Q = q2 * c + (q1 * ell * -dkk if dkk < 0.0 else 0.0)
    Qe = Q + overlap * 0.5 * a_h * ell
    ce2 = c * c + overlap * 0.25 * w2_h * ell * ell
    dt = ell / (Qe + sqrt(Qe * Qe + ce2) + 1e-300)
    if a_h > 0.0 or w2_h > 0.0:
        Qh = 0.5 * a_h * ell + overlap * Q
        ch2 = 0.25 * w2_h * ell * ell + overlap * c * c
        dt = min(dt, ell / (Qh + sqrt(Qh * Qh + ch2) + 1e-300))
    return dt


@njit(cache=True, error_model="numpy", parallel=True)
def element_volumes(x, conn, active, dim, tab, c, L, rho, ngp, q1, q2, gam, hg_form, qh,
                    m_el, vol, dt_el, work):
    r"""Volumes ``vol`` (E,) [m^3] at ``x`` and the element steps ``dt_el`` (E,) [s]
    of :func:`element_step` (the element's largest point wave speed ``c``
    (P,), its first point's rate ``L`` (P, 3, 3)) with the hourglass terms of
    one-point elements (``ngp`` 1, ``qh`` > 0: density ``rho`` (P,), base
    vectors ``gam``, element masses ``m_el`` (E,), as :func:`uniform_forces`);
    the state a part needs before its first force pass or after a restart,
    the same bits as the force pass's. ``work``: :func:`block_scratch`."""
    ne = conn.shape[0]
    nen = conn.shape[1]
    for b in prange(block_count(ne)):
        xl = work[b, 0:nen]
        g = work[b, 2 * nen:3 * nen]
        lo, hi = block_span(b, ne)
        for e in range(lo, hi):
            local_coordinates(x, x, 0.0, conn, e, xl)
            V = volume_gradient(xl, dim, tab, g)
            vol[e] = V
            if not active[e]:
                dt_el[e] = np.inf
                continue
            ce = 0.0
            for j in range(ngp):
                ce = max(ce, c[e * ngp + j])
            p = e * ngp
            dkk = L[p, 0, 0] + L[p, 1, 1] + L[p, 2, 2]
            _, a_h, w2_h, ov = element_hourglass_rates(xl, g, V, gam, hg_form,
                                                       qh if ngp == 1 else 0.0, rho[p], ce,
                                                       dim, m_el[e])
            dt_el[e] = element_step(char_length(g, V), ce, dkk, q1, q2, a_h, w2_h, ov)


@njit(cache=True, error_model="numpy", parallel=True)
def uniform_strain_rate(x, v, conn, active, m_el, dt, dim, tab, L, rho, work):
    r"""Velocity gradient and density of one-point elements (mid-step geometry).

    For each active element: :math:`L = \sum_I \mathbf v_I \otimes \mathbf b_I`
    and the density ``rho = m_el / V`` (E,) on the mid-step geometry
    :math:`\mathbf x - \tfrac{\Delta t}2\mathbf v` (:math:`b = \partial
    V/\partial x / V`), so the material's energy increment :math:`\Delta
    t\,\bar\sigma:D / \rho` is the stress power of the mid-step volume (with
    the volume at :math:`n+1` the energy balance would err at first order in
    dt). ``L`` (E, 3, 3) out [1/s] (zz = 0 in 2D); ``work``:
    :func:`block_scratch`.
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    for b in prange(block_count(ne)):
        xl = work[b, 0:nen]
        vl = work[b, nen:2 * nen]
        g = work[b, 2 * nen:3 * nen]
        lo, hi = block_span(b, ne)
        for e in range(lo, hi):
            if active[e] == 0:
                continue
            element_nodes(x, v, 0.5 * dt, conn, e, xl, vl)
            vm = volume_gradient(xl, dim, tab, g)
            inv = 1.0 / vm if vm > 0.0 else 0.0
            rho[e] = m_el[e] * inv  # mid-step: the stress power sigma:D V^(n+1/2) dt
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for I in range(nen):
                        s += vl[I, i] * g[I, j]
                    L[e, i, j] = s * inv


@njit(cache=True, error_model="numpy")
def bulk_viscosity(rho, c, ell, dkk, q1, q2):
    r"""Bulk-viscosity pressure :math:`q = \rho\ell(Q_1\ell\dot\varepsilon_{kk}^2 -
    Q_2 c\dot\varepsilon_{kk})` for :math:`\dot\varepsilon_{kk} < 0`, else 0 [Pa]."""
    if dkk >= 0.0:
        return 0.0
    return rho * ell * (q1 * ell * dkk * dkk - q2 * c * dkk)


@njit(cache=True, error_model="numpy", parallel=True)
def uniform_forces(x, v, conn, active, sig, L, rho, c, e_spec, e_av, dim, tab, gam,
                   hg_form, qh, hg, e_hg, q1, q2, dt, vol, dt_el, fe, work, m_el):
    r"""Nodal forces (E, nen, 3) of one-point elements: stress, bulk viscosity, hourglass.

    The geometry at :math:`n+1` (``x`` (N, 3)) is computed here, element by
    element: the volumes ``vol`` (E,) [m^3] and the element steps ``dt_el``
    (E,) [s] (:func:`element_step`) are written on the way. Stress ``sig``
    (E, 3, 3) [Pa], density ``rho``, wave speed ``c``, rate ``L`` of
    :func:`uniform_strain_rate`; ``v`` (N, 3) at :math:`n+\tfrac12`; ``gam``
    (modes, nen) hourglass base vectors; ``hg_form`` :data:`HG_VISCOUS` or
    :data:`HG_STIFFNESS`, ``qh`` its coefficient; ``hg`` (E, 4, 3)
    stiffness-form generalised forces [N] (updated); ``e_hg`` (E,) hourglass
    work [J] (updated); bulk viscosity ``q1`` (quadratic), ``q2`` (linear),
    whose heat goes to ``e_spec`` and ``e_av`` (E,) [J/kg]; ``work``:
    :func:`block_scratch`; ``m_el`` (E,) the element masses [kg] of the
    hourglass control's terms in the element step (:func:`hourglass_rates`).
    Equations: module docstring and
    :func:`hourglass_resultants`.
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    nm = gam.shape[0]
    for b in prange(block_count(ne)):
        xl = work[b, 0:nen]
        vl = work[b, nen:2 * nen]
        g = work[b, 2 * nen:3 * nen]
        Q = work[b, 3 * nen:3 * nen + nm]
        M = work[b, 3 * nen + nm:3 * nen + nm + 3]
        lo, hi = block_span(b, ne)
        for e in range(lo, hi):
            if active[e] == 0:
                for I in range(nen):
                    for k in range(3):
                        fe[e, I, k] = 0.0
                dt_el[e] = np.inf
                continue
            element_nodes(x, v, 0.0, conn, e, xl, vl)
            V = volume_gradient(xl, dim, tab, g)
            vol[e] = V
            ell = char_length(g, V)
            dkk = L[e, 0, 0] + L[e, 1, 1] + L[e, 2, 2]
            q = bulk_viscosity(rho[e], c[e], ell, dkk, q1, q2)
            if q > 0.0 and rho[e] > 0.0:
                heat = -dt * q * dkk / rho[e]
                e_spec[e] += heat
                e_av[e] += heat
            coef, a_h, w2_h, ov = element_hourglass_rates(xl, g, V, gam, hg_form, qh, rho[e],
                                                          c[e], dim, m_el[e])
            dt_el[e] = element_step(ell, c[e], dkk, q1, q2, a_h, w2_h, ov)
            hourglass = qh > 0.0 and V > 0.0
            if hourglass:
                e_hg[e] += dt * hourglass_resultants(e, vl, xl, g, V, gam, hg_form, coef,
                                                     hg, dt, dim, Q, M)
            else:
                M[:] = 0.0
            # f_iI = -(sigma_ij - q delta_ij - M_ij / V) dV/dx_jI - sum_a Q_ai Gamma_aI
            s00 = sig[e, 0, 0] - q - M[0, 0]
            s01 = sig[e, 0, 1] - M[0, 1]
            s02 = sig[e, 0, 2] - M[0, 2]
            s10 = sig[e, 1, 0] - M[1, 0]
            s11 = sig[e, 1, 1] - q - M[1, 1]
            s12 = sig[e, 1, 2] - M[1, 2]
            s20 = sig[e, 2, 0] - M[2, 0]
            s21 = sig[e, 2, 1] - M[2, 1]
            s22 = sig[e, 2, 2] - q - M[2, 2]
            for I in range(nen):
                g0 = g[I, 0]
                g1 = g[I, 1]
                g2 = g[I, 2]
                f0 = s00 * g0 + s01 * g1 + s02 * g2
                f1 = s10 * g0 + s11 * g1 + s12 * g2
                f2 = s20 * g0 + s21 * g1 + s22 * g2
                if hourglass:
                    for a in range(nm):
                        G = gam[a, I]
                        f0 += Q[a, 0] * G
                        f1 += Q[a, 1] * G
                        f2 += Q[a, 2] * G
                fe[e, I, 0] = -f0
                fe[e, I, 1] = -f1
                fe[e, I, 2] = -f2


@njit(cache=True, error_model="numpy", parallel=True)
def reduced_strain_rate(x, v, conn, active, m_el, dt, dim, tab, dN, xl, g, Bg, wg, wm, L,
                        rho, vol):
    r"""Selective-reduced elements: per Gauss point B-bar velocity gradient.

    ``dN`` (ngp, nen, dim) shape derivatives in the parent element. For each
    active element and Gauss point g on the mid-step geometry:
    :math:`L_g = \sum_I \mathbf v_I\otimes \nabla N_I(g)`, its trace replaced
    by that of the uniform gradient (in-plane trace in 2D). Then at
    :math:`\mathbf x^{n+1}`: ``g`` (E, nen, 3) volume derivatives, ``vol`` (E,),
    ``Bg`` (P, nen, 3) the Gauss points' :math:`\nabla N_I`, ``wg`` (P,) their
    :math:`\det J` (weight 1); ``wm`` (P,) the same on the mid-step geometry
    (:func:`weigh_point_work`); ``rho`` (P,) the element density and ``L``
    (P, 3, 3) on the mid-step geometry.
    Point p of element e is ``e * ngp + k``.
    """
    ngp = dN.shape[0]
    nen = conn.shape[1]
    for e in prange(conn.shape[0]):
        if active[e] == 0:
            continue
        for stage in range(2):
            s = 0.5 * dt if stage == 0 else 0.0
            local_coordinates(x, v, s, conn, e, xl[e])
            ve = volume_gradient(xl[e], dim, tab, g[e])
            if stage == 1:
                vol[e] = ve
            trm = 0.0  # trace of the uniform gradient
            for I in range(nen):
                n = conn[e, I]
                trm += v[n, 0] * g[e, I, 0] + v[n, 1] * g[e, I, 1] + v[n, 2] * g[e, I, 2]
            trm = trm / ve if ve > 0.0 else 0.0
            for k in range(ngp):
                p = e * ngp + k
                # J_ab = sum_I x_Ia dN_I/dxi_b (dim x dim)
                J00 = J01 = J02 = J10 = J11 = J12 = J20 = J21 = J22 = 0.0
                for I in range(nen):
                    d0 = dN[k, I, 0]
                    d1 = dN[k, I, 1]
                    J00 += xl[e, I, 0] * d0
                    J01 += xl[e, I, 0] * d1
                    J10 += xl[e, I, 1] * d0
                    J11 += xl[e, I, 1] * d1
                    if dim == 3:
                        d2 = dN[k, I, 2]
                        J02 += xl[e, I, 0] * d2
                        J12 += xl[e, I, 1] * d2
                        J20 += xl[e, I, 2] * d0
                        J21 += xl[e, I, 2] * d1
                        J22 += xl[e, I, 2] * d2
                if dim == 2:
                    J22 = 1.0
                det = (J00 * (J11 * J22 - J12 * J21) - J01 * (J10 * J22 - J12 * J20)
                       + J02 * (J10 * J21 - J11 * J20))
                inv = 1.0 / det if det != 0.0 else 0.0
                # inverse transpose rows: grad N = J^-T dN/dxi
                i00 = (J11 * J22 - J12 * J21) * inv
                i01 = (J02 * J21 - J01 * J22) * inv
                i02 = (J01 * J12 - J02 * J11) * inv
                i10 = (J12 * J20 - J10 * J22) * inv
                i11 = (J00 * J22 - J02 * J20) * inv
                i12 = (J02 * J10 - J00 * J12) * inv
                i20 = (J10 * J21 - J11 * J20) * inv
                i21 = (J01 * J20 - J00 * J21) * inv
                i22 = (J00 * J11 - J01 * J10) * inv
                for I in range(nen):
                    d0 = dN[k, I, 0]
                    d1 = dN[k, I, 1]
                    d2 = dN[k, I, 2] if dim == 3 else 0.0
                    # dN/dx_a = sum_b dN/dxi_b (J^-1)_ba
                    Bg[p, I, 0] = d0 * i00 + d1 * i10 + d2 * i20
                    Bg[p, I, 1] = d0 * i01 + d1 * i11 + d2 * i21
                    Bg[p, I, 2] = (d0 * i02 + d1 * i12 + d2 * i22) if dim == 3 else 0.0
                if stage == 1:
                    wg[p] = det
                    continue
                wm[p] = det
                rho[p] = m_el[e] / ve if ve > 0.0 else 0.0  # mid-step, as above
                tr = 0.0
                for i in range(3):
                    for j in range(3):
                        sm = 0.0
                        for I in range(nen):
                            sm += v[conn[e, I], i] * Bg[p, I, j]
                        L[p, i, j] = sm
                    tr += L[p, i, i]
                corr = (trm - tr) / dim
                for i in range(dim):
                    L[p, i, i] += corr


@njit(cache=True, error_model="numpy", parallel=True)
def reduced_forces(conn, active, sig, L, rho, c, e_spec, e_av, g, vol, Bg, wg, q1, q2,
                   dt, dim, dt_el, fe):
    r"""Nodal forces (E, nen, 3) of selective-reduced elements (B-bar, module docstring).

    Bulk viscosity from the element's mean volumetric rate (the points share
    it), heat shared evenly by the points; ``dt_el`` (E,) out, the element
    steps (:func:`element_step` with the element's largest wave speed), 0
    for an element with an inverted Gauss point (:math:`\det J \le 0`; its
    mean volume may still be positive): the point's negative weight turns its
    stiffness into a source of energy, so the run stops there on the
    time-step guard, naming the element (LS-DYNA's negative-volume error).
    """
    ngp = wg.shape[0] // conn.shape[0]
    nen = conn.shape[1]
    for e in prange(conn.shape[0]):
        for I in range(nen):
            for k in range(3):
                fe[e, I, k] = 0.0
        if active[e] == 0:
            dt_el[e] = np.inf
            continue
        V = vol[e]
        p0 = e * ngp
        ell = char_length(g[e], V)
        dkk = L[p0, 0, 0] + L[p0, 1, 1] + L[p0, 2, 2]
        cmax = 0.0
        for k in range(ngp):
            cmax = max(cmax, c[p0 + k])
        dt_el[e] = element_step(ell, cmax, dkk, q1, q2, 0.0, 0.0, 0.0)
        for k in range(ngp):
            if wg[p0 + k] <= 0.0:
                dt_el[e] = 0.0
        q = bulk_viscosity(rho[p0], cmax, ell, dkk, q1, q2)
        if q > 0.0 and rho[p0] > 0.0:
            heat = -dt * q * dkk / rho[p0]
            for k in range(ngp):
                e_spec[p0 + k] += heat
                e_av[p0 + k] += heat
        for k in range(ngp):
            p = p0 + k
            w = wg[p]
            tr = 0.0
            for i in range(dim):
                tr += sig[p, i, i]
            for I in range(nen):
                for i in range(3):
                    s = 0.0
                    for j in range(3):
                        s += sig[p, i, j] * Bg[p, I, j]
                    if i < dim:
                        s += tr / dim * (g[e, I, i] / V - Bg[p, I, i])
                    fe[e, I, i] -= w * s
        for I in range(nen):
            for i in range(dim):
                fe[e, I, i] += q * g[e, I, i]


@njit(cache=True, error_model="numpy", parallel=True)
def weigh_point_work(e, e_old, rho, wm, m):
    r"""Book each point's material work with its own volume (selective-reduced).

    A material adds :math:`\Delta e = \Delta t\,\bar\sigma:\mathbf D/\rho`
    to the specific energy ``e`` (P,) [J/kg] of a point of mass ``m`` (P,)
    [kg] with the density ``rho`` (P,) [kg/m^3] it was given (the element's,
    :math:`m_e/V`); the point's work is that stress power over its own
    volume, the mid-step Gauss volume ``wm`` (P,) [m^3] (:math:`\det J`, the
    point's weight in the forces, Hughes 1980; module docstring), so the
    increment is scaled by :math:`\rho\,J_g/m_g`:

    .. math:: e \leftarrow e_{old} + (e - e_{old})\,\rho\, J_g / m_g

    (``e_old`` (P,) before the update). Points without mass (eroded) are left
    as they are.
    """
    for p in prange(e.shape[0]):
        if m[p] > 0.0:
            e[p] = e_old[p] + (e[p] - e_old[p]) * (rho[p] * wm[p] / m[p])


#: blocks of the parallel minimum in :func:`min_time_step`
DT_BLOCKS = 64


@njit(cache=True, error_model="numpy", parallel=True)
def min_time_step(dt_el, dt_mass, cfl, blk_t, blk_k):
    r"""The part's stable step ``cfl * min(dt_el)`` and the controlling element.

    ``dt_el`` (E,) the element steps of the last force pass
    (:func:`element_step`, ``inf`` for inactive elements), each times its
    mass-scaling factor ``dt_mass`` (E,) (1 without). The minimum is
    taken in parallel over ``blk_t.size`` contiguous blocks (scratch ``blk_t``
    (B,) float, ``blk_k`` (B,) int64), then over the blocks in order, so the
    controlling element is the first one with the smallest step, as a serial
    loop would find it.
    """
    ne = dt_el.shape[0]
    nb = blk_t.shape[0]
    size = (ne + nb - 1) // nb
    for b in prange(nb):
        best = np.inf
        k = 0
        for e in range(b * size, min(ne, (b + 1) * size)):
            d = dt_el[e] * dt_mass[e]
            if d < best:
                best = d
                k = e
        blk_t[b] = best
        blk_k[b] = k
    best = np.inf
    k = 0
    for b in range(nb):
        if blk_t[b] < best:
            best = blk_t[b]
            k = blk_k[b]
    return cfl * best, k
