r"""Hourglass control of the one-point solid elements (hex8, quad4) and its
share of the element's stable step; the element passes that use it:
:mod:`.solid` (and :mod:`.hex_lanes`).

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

**Stable step with the hourglass control** (:func:`hourglass_rates`,
:func:`hourglass_overlap`, :func:`element_step`; docs/theory.md): the
hourglass forces are explicit too. On the nodes of one element they act as
:math:`\mathbf f = -\,a_h\, \Gamma^{\gamma T}\Gamma^{\gamma}\,\mathbf v` (viscous;
:math:`k_h` on the displacements for the stiffness form), with
:math:`\Gamma^\gamma` the shape vectors :math:`\gamma_{\alpha I}` above. The
velocity-lagged central difference is stable where :math:`\lambda_{max}(M^{-1}
(\Delta t\,C/2 + \Delta t^2 K/4)) \le 1` (for one mode the damped
oscillator's limit :math:`\Delta t \le 2/(A + \sqrt{A^2 + \omega^2})`,
Belytschko, Liu & Moran 2000, sec. 6.2), and the assembled
:math:`\lambda_{max}` is at most the largest element's formed with the
element's own share :math:`m = m_e/n_{en}` of each node's mass (Irons'
bound; a node's whole mass is not a bound where several distorted elements
share it). So on the element: a damping rate :math:`A_h = a_h\lambda/(2m)`
(viscous) or a stiffness :math:`\omega_h^2 = k_h\lambda/m`, :math:`\lambda`
the largest eigenvalue of the Gram matrix :math:`G_{\alpha\beta} = \sum_I
\gamma_{\alpha I}\gamma_{\beta I}`, bounded by the smaller of its trace and
Gershgorin's row sums (:func:`hourglass_bound`; :math:`n_{en}`, exact, for
an undistorted element). The stress acts on the nodal fields
:math:`\mathbf u_I = S\mathbf b_I`, the hourglass control on the span of the
shape vectors, orthogonal to the linear fields; with :math:`c_\theta` the
cosine of the smallest angle between the two (:func:`hourglass_overlap`),
:math:`x = \Delta t A_h + \Delta t^2\omega_h^2/4` and :math:`y = \Delta t\,
2Q/\ell + \Delta t^2 c^2/\ell^2` the condition holds where :math:`x +
c_\theta y \le 1` and :math:`y + c_\theta x \le 1`: the smaller of two
damped-oscillator limits (:func:`element_step`). An undistorted element
(:math:`c_\theta = 0`) takes the smaller of its own step and the hourglass
term's own (:math:`2m/(a_h\lambda)`, :math:`2/\omega_h`), which at
:math:`Q_{hg} \le 0.15` is its own; a distorted one a joint step (the limit
of the sum at :math:`c_\theta = 1`). LS-DYNA's element step has no
hourglass term; it deletes distorted elements through its erosion criteria.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...simd import sqrt


HG_VISCOUS = 0


HG_STIFFNESS = 1


#: ``mu - 1`` of :func:`overlap_from_moments` below which the overlap is 0: a
#: parallelepiped's ``mu`` is 1 up to round-off (about 1e-15), whose square
#: root (3e-8) would pass one ulp of a node's position on to the step as a
#: change of 1e-8; an overlap under 1e-5 changes the step by less than that
OVERLAP_ROUNDOFF = 1e-10


@njit(cache=True, error_model="numpy")
def hourglass_overlap(xl, g, V, dim):
    r"""The bound :math:`c_\theta` of :func:`element_step` on the cosine of the
    smallest angle between the element's stiffness and hourglass subspaces
    [-] (module docstring, "Stable step with the hourglass control"):
    :math:`c_\theta^2 = 1 - 1/\mu`, :math:`\mu = \mathrm{tr}(G_x G_b) - (d - 1)`
    (0 where :math:`\mu \le 1 +` :data:`OVERLAP_ROUNDOFF`), :math:`G_x =
    \sum_I \tilde{\mathbf x}_I\otimes\tilde{\mathbf x}_I` of the node
    coordinates about their mean,
    :math:`G_b = \sum_I \mathbf b_I\otimes\mathbf b_I`, :math:`\mathbf b_I =
    \partial V/\partial\mathbf x_I / V`. 0 for a parallelepiped
    (:math:`G_x G_b = \mathbf 1`). ``xl``, ``g`` (nen, 3) node coordinates [m]
    and volume derivatives [m^2], ``V`` > 0 [m^3], ``dim`` 2 or 3. The
    reference of the lane pass (:func:`.hex_lanes.overlap_lanes`, the same
    operations in the same order)."""
    nen = xl.shape[0]
    m0 = m1 = m2 = 0.0
    for I in range(nen):
        m0 += xl[I, 0]
        m1 += xl[I, 1]
        m2 += xl[I, 2]
    m0 /= nen
    m1 /= nen
    m2 /= nen
    p00 = p01 = p02 = p11 = p12 = p22 = 0.0
    r00 = r01 = r02 = r11 = r12 = r22 = 0.0
    for I in range(nen):
        y0 = xl[I, 0] - m0
        y1 = xl[I, 1] - m1
        y2 = xl[I, 2] - m2
        p00 += y0 * y0
        p01 += y0 * y1
        p02 += y0 * y2
        p11 += y1 * y1
        p12 += y1 * y2
        p22 += y2 * y2
        r00 += g[I, 0] * g[I, 0]
        r01 += g[I, 0] * g[I, 1]
        r02 += g[I, 0] * g[I, 2]
        r11 += g[I, 1] * g[I, 1]
        r12 += g[I, 1] * g[I, 2]
        r22 += g[I, 2] * g[I, 2]
    return overlap_from_moments(p00, p01, p02, p11, p12, p22, r00, r01, r02, r11, r12, r22,
                                V, dim)


@njit(cache=True, error_model="numpy")
def overlap_from_moments(p00, p01, p02, p11, p12, p22, r00, r01, r02, r11, r12, r22, V,
                         dim):
    r""":math:`c_\theta` of :func:`hourglass_overlap` from the six entries of
    :math:`G_x` (``p``) [m^2] and of :math:`V^2 G_b` (``r``) [m^4]."""
    t = (p00 * r00 + p11 * r11 + p22 * r22 + 2.0 * (p01 * r01 + p02 * r02 + p12 * r12))
    mu = t / (V * V) - (dim - 1)
    c2 = 1.0 - 1.0 / mu if mu > 1.0 + OVERLAP_ROUNDOFF else 0.0
    return sqrt(c2)


@njit(cache=True, error_model="numpy")
def element_hourglass_rates(xl, g, V, gam, hg_form, qh, rho, c, dim, m_el):
    """The hourglass coefficient (:func:`hourglass_coefficient`),
    :func:`hourglass_rates` and :func:`hourglass_overlap` of an element
    (coordinates ``xl``, volume derivatives ``g`` (nen, 3), volume ``V``,
    density ``rho``, wave speed ``c``, mass ``m_el`` [kg], each node's share
    ``m_el / nen``); (0, 0, 0, 0) without hourglass control (``qh`` 0) or at
    ``V`` <= 0."""
    if not (qh > 0.0 and V > 0.0):
        return 0.0, 0.0, 0.0, 0.0
    bb = 0.0
    if hg_form != HG_VISCOUS:
        for I in range(g.shape[0]):
            bb += g[I, 0] ** 2 + g[I, 1] ** 2 + g[I, 2] ** 2
    face = hourglass_face(V, dim) if hg_form == HG_VISCOUS else 0.0
    coef = hourglass_coefficient(hg_form, qh, rho, c, face, bb, V, dim)
    a_h, w2_h = hourglass_rates(hourglass_bound(xl, g, V, gam), coef, m_el / g.shape[0],
                                hg_form)
    return coef, a_h, w2_h, hourglass_overlap(xl, g, V, dim)


@njit(cache=True, error_model="numpy")
def hourglass_bound(xl, g, V, gam):
    r"""The bound :math:`\lambda` of :func:`hourglass_rates`: the smaller of the
    trace of the Gram matrix of the shape vectors, :math:`\sum_{\alpha
    I}\gamma_{\alpha I}^2` (:math:`\ge\lambda_{max}`, the matrix being positive
    semi-definite), and :func:`hourglass_gram_bound` (Gershgorin; it can exceed
    the trace, and both bound :math:`\lambda_{max}`; for an undistorted
    element it is exact, :math:`n_{en}`, the trace 4 times that for a hex).
    Arguments as :func:`hourglass_gram_bound`."""
    nm, nen = gam.shape
    inv_v = 1.0 / V
    tr = 0.0
    for a in range(nm):
        for I in range(nen):
            gm = shape_vector(xl, g, inv_v, gam, a, I)
            tr += gm * gm
    return min(tr, hourglass_gram_bound(xl, g, V, gam))


@njit(cache=True, error_model="numpy")
def hourglass_gram_bound(xl, g, V, gam):
    r"""Gershgorin's bound :math:`\max_\alpha \sum_\beta |G_{\alpha\beta}|` of the
    largest eigenvalue of the Gram matrix :math:`G_{\alpha\beta} = \sum_I
    \gamma_{\alpha I}\gamma_{\beta I}` of the hourglass shape vectors
    :math:`\gamma_{\alpha I} = \Gamma_{\alpha I} - \mathbf h_\alpha\cdot
    \partial V/\partial\mathbf x_I`, :math:`\mathbf h_\alpha = \sum_J
    \Gamma_{\alpha J}\mathbf x_J / V` (module docstring, "Stable step of the
    hourglass control"; dimensionless, ``nen`` for an undistorted element).
    ``xl``, ``g`` (nen, 3) node coordinates [m] and volume derivatives [m^2],
    ``V`` > 0 [m^3], ``gam`` (modes, nen) the base vectors. The reference of
    the lane pass (:func:`.hex_lanes.force_lanes`: the same operations in the
    same order), so each shape vector is formed where it is used."""
    nm, nen = gam.shape
    inv_v = 1.0 / V
    lam = 0.0
    for a in range(nm):
        row = 0.0
        for b in range(nm):
            s = 0.0
            for I in range(nen):
                s += (shape_vector(xl, g, inv_v, gam, a, I)
                      * shape_vector(xl, g, inv_v, gam, b, I))
            row += abs(s)
        lam = max(lam, row)
    return lam


@njit(cache=True, error_model="numpy")
def shape_vector(xl, g, inv_v, gam, a, I):
    r""":math:`\gamma_{\alpha I} = \Gamma_{\alpha I} - \mathbf h_\alpha\cdot
    \partial V/\partial\mathbf x_I` of :func:`hourglass_gram_bound` (``inv_v`` =
    1/V)."""
    h0, h1, h2 = hourglass_moment(xl, gam, a, inv_v)
    return gam[a, I] - (h0 * g[I, 0] + h1 * g[I, 1] + h2 * g[I, 2])


@njit(cache=True, error_model="numpy")
def hourglass_moment(xl, gam, a, inv_v):
    r""":math:`\mathbf h_\alpha = \sum_J \Gamma_{\alpha J}\mathbf x_J / V` [-] of
    mode ``a`` (``xl`` (nen, 3) node coordinates [m], ``inv_v`` = 1/V [1/m^3])."""
    h0 = h1 = h2 = 0.0
    for J in range(xl.shape[0]):
        G = gam[a, J]
        h0 += G * xl[J, 0]
        h1 += G * xl[J, 1]
        h2 += G * xl[J, 2]
    return h0 * inv_v, h1 * inv_v, h2 * inv_v


@njit(cache=True, error_model="numpy")
def hourglass_rates(lam, coef, m_share, hg_form):
    r"""The hourglass control's terms of :func:`element_step` (module
    docstring): the damping rate :math:`A_h = a_h\lambda/(2m)` [1/s] (viscous)
    and the stiffness :math:`\omega_h^2 = k_h\lambda/m` [1/s^2] (stiffness
    form), the other 0; both 0 without hourglass control (``coef`` <= 0).
    ``lam`` the bound of :func:`hourglass_bound`, ``coef`` :math:`a_h` [kg/s]
    or :math:`k_h` [N/m], ``m_share`` the element's share of each node's mass
    [kg] (its mass over ``nen``, not the node's whole mass: module docstring).
    Alone, :math:`A_h` allows the step :math:`1/A_h = 2m/(a_h\lambda)` and
    :math:`\omega_h^2` allows :math:`2/\omega_h`."""
    if coef <= 0.0 or lam <= 0.0:
        return 0.0, 0.0
    if hg_form == HG_VISCOUS:
        return 0.5 * coef * lam / m_share, 0.0
    return 0.0, coef * lam / m_share


@njit(cache=True, error_model="numpy")
def hourglass_face(V, dim):
    r""":math:`V^{(d-1)/d}` [m^2 in 3D, m in 2D] of the viscous hourglass
    coefficient (:func:`hourglass_coefficient`), without a general power."""
    return np.cbrt(V) ** 2 if dim == 3 else math.sqrt(V)


@njit(cache=True, error_model="numpy")
def hourglass_coefficient(hg_form, qh, rho, c, face, bb, V, dim):
    r"""The hourglass control's coefficient: viscous :math:`a_h = Q_{hg}\rho c
    V^{(d-1)/d}/4` [kg/s] (``face`` :func:`hourglass_face`), stiffness
    :math:`k_h = Q_{hg}\rho c^2 \sum b^2/(V d)` [N/m] (``bb``
    :math:`\sum_{iI} (\partial V/\partial x_{iI})^2` [m^4], ``V`` [m^3] > 0;
    LS-DYNA's forms 1 and 4, Flanagan & Belytschko 1981). ``qh`` :math:`Q_{hg}`,
    ``rho`` [kg/m^3], ``c`` [m/s]."""
    if hg_form == HG_VISCOUS:
        return qh * rho * c * face / 4.0
    return qh * rho * c * c * bb / (V * dim)


@njit(cache=True, error_model="numpy")
def hourglass_resultants(e, vl, xl, g, V, gam, hg_form, coef, hg, dt, dim, Q, M):
    r"""Hourglass generalised forces ``Q`` (modes, 3) [N] of element ``e`` and
    their share ``M`` (3, 3) [N m] of the force pass; returns their power [W].

    With :math:`\mathbf h_\alpha = \sum_J \Gamma_{\alpha J}\mathbf x_J` the
    shape vectors are :math:`\gamma_{\alpha I} = \Gamma_{\alpha I} - \mathbf
    h_\alpha\cdot\mathbf b_I`, so the rates need no per-node shape vector:
    :math:`\dot q_{i\alpha} = \sum_I v_{iI}\Gamma_{\alpha I} - \bar L_{ij}
    h_{\alpha j}` with :math:`\bar L = \sum_I \mathbf v_I\otimes\mathbf b_I`
    (the gradient on the end-of-step geometry), and the forces
    :math:`-\sum_\alpha Q_{i\alpha}\gamma_{\alpha I} = -\sum_\alpha
    Q_{i\alpha}\Gamma_{\alpha I} + (M_{ij}/V)\, \partial V/\partial x_{jI}`
    with :math:`M_{ij} = \sum_\alpha Q_{i\alpha} h_{\alpha j}` (module
    docstring for :math:`Q`; ``coef`` is :math:`a_h` or :math:`k_h`; the
    stiffness form accumulates ``hg`` (E, modes, 3)). ``xl``, ``g`` (nen, 3)
    the element's node coordinates and volume derivatives at :math:`n+1`,
    ``vl`` (nen, 3) its node velocities at :math:`n+\tfrac12`.
    """
    nen = xl.shape[0]
    inv_v = 1.0 / V
    Lb00 = Lb01 = Lb02 = Lb10 = Lb11 = Lb12 = Lb20 = Lb21 = Lb22 = 0.0
    for I in range(nen):
        v0 = vl[I, 0]
        v1 = vl[I, 1]
        v2 = vl[I, 2]
        Lb00 += v0 * g[I, 0]
        Lb01 += v0 * g[I, 1]
        Lb02 += v0 * g[I, 2]
        Lb10 += v1 * g[I, 0]
        Lb11 += v1 * g[I, 1]
        Lb12 += v1 * g[I, 2]
        Lb20 += v2 * g[I, 0]
        Lb21 += v2 * g[I, 1]
        Lb22 += v2 * g[I, 2]
    for i in range(3):
        for j in range(3):
            M[i, j] = 0.0
    power = 0.0
    for a in range(gam.shape[0]):
        h0, h1, h2 = hourglass_moment(xl, gam, a, inv_v)
        w0 = w1 = w2 = 0.0
        for J in range(nen):
            G = gam[a, J]
            w0 += G * vl[J, 0]
            w1 += G * vl[J, 1]
            w2 += G * vl[J, 2]
        qd0 = w0 - (Lb00 * h0 + Lb01 * h1 + Lb02 * h2)
        qd1 = w1 - (Lb10 * h0 + Lb11 * h1 + Lb12 * h2)
        qd2 = w2 - (Lb20 * h0 + Lb21 * h1 + Lb22 * h2)
        if hg_form == HG_VISCOUS:
            Q[a, 0] = coef * qd0
            Q[a, 1] = coef * qd1
            Q[a, 2] = coef * qd2
        else:
            hg[e, a, 0] += dt * coef * qd0
            hg[e, a, 1] += dt * coef * qd1
            hg[e, a, 2] += dt * coef * qd2
            Q[a, 0] = hg[e, a, 0]
            Q[a, 1] = hg[e, a, 1]
            Q[a, 2] = hg[e, a, 2]
        if dim == 2:
            Q[a, 2] = 0.0
        power += Q[a, 0] * qd0 + Q[a, 1] * qd1 + Q[a, 2] * qd2
        for i in range(3):  # h already carries 1/V: M / V
            M[i, 0] += Q[a, i] * h0
            M[i, 1] += Q[a, i] * h1
            M[i, 2] += Q[a, i] * h2
    return power
