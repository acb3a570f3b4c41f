r"""Numba kernels of the solid elements: hex8 (3D) and quad4 (2D plane strain).

One code path for both (``dim`` 3 or 2, ``nen`` 8 or 4). Element loops run in
``prange`` and write only their own element's rows (the element nodal forces
``fe`` (E, nen, 3)); :func:`.gather.gather_loads` then sums them per node
from the node-to-element list, so no two threads write the same memory.

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

**Hourglass control** (Flanagan & Belytschko 1981, eqs. 33-36 and 52;
LS-DYNA Theory Manual, "Hourglass control", types 2 and 4): hourglass shape
vectors :math:`\gamma_{\alpha I} = \Gamma_{\alpha I} - (\sum_J \Gamma_{\alpha J}
x_{jJ})\, b_{jI}`, hourglass rates :math:`\dot q_{i\alpha} = \sum_I v_{iI}
\gamma_{\alpha I}` and forces :math:`f^{hg}_{iI} = -\sum_\alpha Q_{i\alpha}
\gamma_{\alpha I}` with

* viscous form: :math:`Q_{i\alpha} = a_h \dot q_{i\alpha}`,
  :math:`a_h = Q_{hg}\, \rho\, c\, V^{(d-1)/d} / 4`;
* stiffness form: :math:`\dot Q_{i\alpha} = k_h \dot q_{i\alpha}`,
  :math:`k_h = Q_{hg}\, \rho c^2\, V\, \sum_{iI} b_{iI}^2 / d`
  (Flanagan & Belytschko's :math:`\kappa(\lambda + 2\mu) b\cdot b\, V/3` in 3D).

The hourglass forces are orthogonal to the linear fields, so they vanish in
the patch test and do no work in a rigid motion; their work is booked per
element in ``e_hg`` (part of the internal energy).

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

import math

import numpy as np
from numba import njit, prange

from .hex_gradient import hex_volume_gradient

HG_VISCOUS = 0
HG_STIFFNESS = 1


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
    r"""Characteristic length :math:`\ell = 2/\sqrt{n_{en}\sum b^2}`, :math:`b = g / V` [m]."""
    s = 0.0
    for I in range(g.shape[0]):
        s += g[I, 0] ** 2 + g[I, 1] ** 2 + g[I, 2] ** 2
    if s <= 0.0 or vol <= 0.0:
        return 0.0
    return 2.0 * vol / math.sqrt(g.shape[0] * s)


@njit(cache=True, error_model="numpy", parallel=True)
def uniform_strain_rate(x, v, conn, active, m_el, dt, dim, tab, xl, g, L, rho, vol):
    r"""Velocity gradient, volume and density of one-point elements.

    For each active element: :math:`L = \sum_I \mathbf v_I \otimes \mathbf b_I`
    and the density ``rho = m_el / V`` (E,) on the mid-step geometry (:math:`b
    = \partial V/\partial x / V`), so the material's energy increment
    :math:`\Delta t\,\bar\sigma:D / \rho` is the stress power of the mid-step
    volume (with the volume at :math:`n+1` the energy balance would err at
    first order in dt); then the volume derivatives ``g`` (E, nen, 3) and
    volume ``vol`` (E,) at :math:`\mathbf x^{n+1}`. ``xl`` (E, nen, 3)
    scratch. ``L`` (E, 3, 3) out [1/s] (zz = 0 in 2D).
    """
    for e in prange(conn.shape[0]):
        if active[e] == 0:
            continue
        local_coordinates(x, v, 0.5 * dt, conn, e, xl[e])
        vm = volume_gradient(xl[e], dim, tab, g[e])
        inv = 1.0 / vm if vm > 0.0 else 0.0
        rho[e] = m_el[e] * inv  # mid-step: the stress power sigma:D V^(n+1/2) dt
        for i in range(3):
            for j in range(3):
                s = 0.0
                for I in range(conn.shape[1]):
                    s += v[conn[e, I], i] * g[e, I, j]
                L[e, i, j] = s * inv
        local_coordinates(x, v, 0.0, conn, e, xl[e])
        vol[e] = volume_gradient(xl[e], dim, tab, g[e])


@njit(cache=True, error_model="numpy")
def bulk_viscosity(rho, c, ell, dkk, q1, q2):
    r"""Bulk-viscosity pressure :math:`q = \rho\ell(Q_1\ell\dot\varepsilon_{kk}^2 -
    Q_2 c\dot\varepsilon_{kk})` for :math:`\dot\varepsilon_{kk} < 0`, else 0 [Pa]."""
    if dkk >= 0.0:
        return 0.0
    return rho * ell * (q1 * ell * dkk * dkk - q2 * c * dkk)


@njit(cache=True, error_model="numpy", parallel=True)
def uniform_forces(v, conn, active, sig, L, rho, c, e_spec, e_av, xl, g, vol, gam,
                   hg_form, qh, hg, e_hg, q1, q2, dt, dim, fe):
    r"""Nodal forces (E, nen, 3) of one-point elements: stress, bulk viscosity, hourglass.

    Inputs at :math:`n+1`: ``xl``, ``g``, ``vol`` of :func:`uniform_strain_rate`,
    stress ``sig`` (E, 3, 3) [Pa], density ``rho``, wave speed ``c``;
    ``v`` (N, 3) at :math:`n+\tfrac12`; ``gam`` (modes, nen) hourglass base
    vectors; ``hg_form`` :data:`HG_VISCOUS` or :data:`HG_STIFFNESS`, ``qh``
    its coefficient; ``hg`` (E, 4, 3) stiffness-form generalised forces
    [N] (updated); ``e_hg`` (E,) hourglass work [J] (updated); bulk
    viscosity ``q1`` (quadratic), ``q2`` (linear), whose heat goes to
    ``e_spec`` and ``e_av`` (E,) [J/kg]. Equations: module docstring.
    """
    nen = conn.shape[1]
    nm = gam.shape[0]
    for e in prange(conn.shape[0]):
        if active[e] == 0:
            for I in range(nen):
                for k in range(3):
                    fe[e, I, k] = 0.0
            continue
        V = vol[e]
        ell = char_length(g[e], V)
        dkk = L[e, 0, 0] + L[e, 1, 1] + L[e, 2, 2]
        q = bulk_viscosity(rho[e], c[e], ell, dkk, q1, q2)
        if q > 0.0 and rho[e] > 0.0:
            heat = -dt * q * dkk / rho[e]
            e_spec[e] += heat
            e_av[e] += heat
        for I in range(nen):
            for i in range(3):
                s = 0.0
                for j in range(3):
                    s += (sig[e, i, j] - (q if i == j else 0.0)) * g[e, I, j]
                fe[e, I, i] = -s
        if qh <= 0.0 or V <= 0.0:
            continue
        bb = 0.0
        for I in range(nen):
            bb += g[e, I, 0] ** 2 + g[e, I, 1] ** 2 + g[e, I, 2] ** 2
        bb /= V * V
        if hg_form == HG_VISCOUS:
            coef = qh * rho[e] * c[e] * V ** ((dim - 1.0) / dim) / 4.0
        else:
            coef = qh * rho[e] * c[e] * c[e] * V * bb / dim
        inv_v = 1.0 / V  # one division per element, not one per mode and node
        power = 0.0
        for a in range(nm):
            # gamma_aI = Gamma_aI - (sum_J Gamma_aJ x_J) . b_I
            h0 = 0.0
            h1 = 0.0
            h2 = 0.0
            for J in range(nen):
                h0 += gam[a, J] * xl[e, J, 0]
                h1 += gam[a, J] * xl[e, J, 1]
                h2 += gam[a, J] * xl[e, J, 2]
            qd0 = 0.0
            qd1 = 0.0
            qd2 = 0.0
            for I in range(nen):
                gI = gam[a, I] - (h0 * g[e, I, 0] + h1 * g[e, I, 1] + h2 * g[e, I, 2]) * inv_v
                n = conn[e, I]
                qd0 += v[n, 0] * gI
                qd1 += v[n, 1] * gI
                qd2 += v[n, 2] * gI
            if hg_form == HG_VISCOUS:
                Q0 = coef * qd0
                Q1 = coef * qd1
                Q2 = coef * qd2
            else:
                hg[e, a, 0] += dt * coef * qd0
                hg[e, a, 1] += dt * coef * qd1
                hg[e, a, 2] += dt * coef * qd2
                Q0 = hg[e, a, 0]
                Q1 = hg[e, a, 1]
                Q2 = hg[e, a, 2]
            if dim == 2:
                Q2 = 0.0
            power += Q0 * qd0 + Q1 * qd1 + Q2 * qd2
            for I in range(nen):
                gI = gam[a, I] - (h0 * g[e, I, 0] + h1 * g[e, I, 1] + h2 * g[e, I, 2]) * inv_v
                fe[e, I, 0] -= Q0 * gI
                fe[e, I, 1] -= Q1 * gI
                fe[e, I, 2] -= Q2 * gI
        e_hg[e] += dt * power


@njit(cache=True, error_model="numpy", parallel=True)
def reduced_strain_rate(x, v, conn, active, m_el, dt, dim, tab, dN, xl, g, Bg, wg, L, rho,
                        vol):
    r"""Selective-reduced elements: per Gauss point B-bar velocity gradient.

    ``dN`` (ngp, nen, dim) shape derivatives in the parent element. For each
    active element and Gauss point g on the mid-step geometry:
    :math:`L_g = \sum_I \mathbf v_I\otimes \nabla N_I(g)`, its trace replaced
    by that of the uniform gradient (in-plane trace in 2D). Then at
    :math:`\mathbf x^{n+1}`: ``g`` (E, nen, 3) volume derivatives, ``vol`` (E,),
    ``Bg`` (P, nen, 3) the Gauss points' :math:`\nabla N_I`, ``wg`` (P,) their
    :math:`\det J` (weight 1); ``rho`` (P,) the element density and ``L``
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
                   dt, dim, fe):
    r"""Nodal forces (E, nen, 3) of selective-reduced elements (B-bar, module docstring).

    Bulk viscosity from the element's mean volumetric rate (the points share
    it), heat shared evenly by the points.
    """
    ngp = wg.shape[0] // conn.shape[0]
    nen = conn.shape[1]
    for e in prange(conn.shape[0]):
        for I in range(nen):
            for k in range(3):
                fe[e, I, k] = 0.0
        if active[e] == 0:
            continue
        V = vol[e]
        p0 = e * ngp
        ell = char_length(g[e], V)
        dkk = L[p0, 0, 0] + L[p0, 1, 1] + L[p0, 2, 2]
        cmax = 0.0
        for k in range(ngp):
            cmax = max(cmax, c[p0 + k])
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


#: blocks of the parallel minimum in :func:`element_time_step`
DT_BLOCKS = 64


@njit(cache=True, error_model="numpy", parallel=True)
def element_time_step(g, vol, c, L, ngp, active, q1, q2, cfl, blk_t, blk_k):
    r"""Stable step :math:`C\,\ell/(Q + \sqrt{Q^2 + c^2})` of the elements and the
    controlling element (module docstring); ``c`` and ``L`` per point (the
    element's largest c, its first point's volumetric rate).

    The minimum is taken in parallel over ``blk_t.size`` contiguous blocks
    (scratch ``blk_t`` (B,) float, ``blk_k`` (B,) int64), then over the
    blocks in order, so the controlling element is the first one with the
    smallest step, as a serial loop would find it.
    """
    ne = g.shape[0]
    nb = blk_t.shape[0]
    size = (ne + nb - 1) // nb
    for b in prange(nb):
        best = np.inf
        k = 0
        for e in range(b * size, min(ne, (b + 1) * size)):
            if active[e] == 0:
                continue
            ell = char_length(g[e], vol[e])
            ce = 0.0
            for j in range(ngp):
                ce = max(ce, c[e * ngp + j])
            p = e * ngp
            dkk = L[p, 0, 0] + L[p, 1, 1] + L[p, 2, 2]
            Q = q2 * ce + (q1 * ell * -dkk if dkk < 0.0 else 0.0)
            t = ell / (Q + math.sqrt(Q * Q + ce * ce) + 1e-300)
            if t < best:
                best = t
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
