"""CSCM yield surface: shear surface, Rubin three-invariant factor, cap, invariants.

All functions take ``J1`` compression positive (``J1 = -tr(sigma)``, see
:func:`invariants`) in pascals and the packed parameters ``p``
(:mod:`sphdyn.materials.cscm.layout`). Notes sec. 1.4-1.7.
"""

import math

from numba import njit

from ..base import ddot6
from .layout import (P_A1, P_A2, P_ALPHA, P_B1, P_B2, P_BETA, P_D1, P_D2, P_J1APEX,
                     P_KAPPA0, P_L1, P_L2, P_LAMDA, P_R, P_R0_ELASTIC, P_T1, P_T2, P_THETA,
                     P_W, P_X0)


@njit(cache=True, error_model="numpy")
def shear_surface(J1, p):
    """TXC shear failure surface ``Ff(J1) = alpha - lamda exp(-beta J1) + theta J1``.

    Notes sec. 1.5 [R/S]; Murray 2007 ch. 2. Compared with ``sqrt(J2')``.

    Parameters
    ----------
    J1 : float
        First stress invariant, compression positive [Pa].
    p : float64 array
        Packed CSCM parameters (SI).

    Returns
    -------
    float, [Pa].
    """
    return p[P_ALPHA] - p[P_LAMDA] * math.exp(-p[P_BETA] * J1) + p[P_THETA] * J1


@njit(cache=True, error_model="numpy")
def rubin_q(J1, p):
    """Strength ratios ``Q1 = TOR/TXC`` and ``Q2 = TXE/TXC``.

    ``Q_i = alpha_i - lamda_i exp(-beta_i J1) + theta_i J1`` for ``J1 >= 0``;
    held at their ``J1 = 0`` values for tensile pressure (``J1 < 0``): the
    clamp of notes sec. 1.6 [S] (1/sqrt(3), 1/2 with the defaults; holding the
    J1 = 0 value keeps it continuous for user-given ratios: choice [D]).

    Returns
    -------
    (Q1, Q2) : floats [-].
    """
    x = J1 if J1 > 0.0 else 0.0
    q1 = p[P_A1] - p[P_L1] * math.exp(-p[P_B1] * x) + p[P_T1] * x
    q2 = p[P_A2] - p[P_L2] * math.exp(-p[P_B2] * x) + p[P_T2] * x
    return q1, q2


@njit(cache=True, error_model="numpy")
def rubin_factor(q1, q2, bhat):
    """Rubin three-invariant reduction factor ``Rub(beta_hat)``.

    .. math::
        a_0 = 2Q_1^2(Q_2-1),\\ a_1 = \\sqrt3 Q_2 + 2Q_1(Q_2-1),\\ a_2 = Q_2,\\
        a = \\frac{-a_1 + \\sqrt{a_1^2 - 4a_2a_0}}{2a_2}

        b = (2Q_1 + a)^2 - 3,\\ b_0 = -(3 + b - a^2)/4,\\
        b_1 = a(\\cos\\hat\\beta - a\\sin\\hat\\beta),\\
        b_2 = (\\cos\\hat\\beta - a\\sin\\hat\\beta)^2 + b\\sin^2\\hat\\beta

        \\Re = \\frac{-b_1 + \\sqrt{b_1^2 - 4b_2b_0}}{2b_2}

    Notes sec. 1.6 [S]; Rubin (1991). ``Rub(pi/6) = 1`` (TXC),
    ``Rub(0) = Q1`` (TOR), ``Rub(-pi/6) = Q2`` (TXE).

    Parameters
    ----------
    q1, q2 : float
        Strength ratios [-].
    bhat : float
        Lode angle in [-pi/6, pi/6] [rad] (see :func:`invariants`).
    """
    return _rubin_cs(q1, q2, math.cos(bhat), math.sin(bhat))


@njit(cache=True, error_model="numpy")
def _rubin_cs(q1, q2, cb, sb):
    """:func:`rubin_factor` with ``cos(beta_hat)``, ``sin(beta_hat)`` given."""
    a0 = 2.0 * q1 * q1 * (q2 - 1.0)
    a1 = math.sqrt(3.0) * q2 + 2.0 * q1 * (q2 - 1.0)
    a2 = q2
    a = (-a1 + math.sqrt(max(a1 * a1 - 4.0 * a2 * a0, 0.0))) * (0.5 / a2)
    b = (2.0 * q1 + a) ** 2 - 3.0
    b0 = -(3.0 + b - a * a) / 4.0
    cs = cb - a * sb
    b1 = a * cs
    b2 = cs * cs + b * sb * sb
    return (-b1 + math.sqrt(max(b1 * b1 - 4.0 * b2 * b0, 0.0))) * (0.5 / b2)


@njit(cache=True, error_model="numpy")
def _j2_j3(dev):
    """``J2' = dev:dev/2`` and ``J3' = det(dev)`` of a deviator 6-tuple."""
    J3 = (dev[0] * (dev[1] * dev[2] - dev[4] * dev[4])
          - dev[3] * (dev[3] * dev[2] - dev[4] * dev[5])
          + dev[5] * (dev[3] * dev[4] - dev[1] * dev[5]))
    return 0.5 * ddot6(dev, dev), J3


@njit(cache=True, error_model="numpy")
def invariants(s):
    """Invariants of a tension-positive stress 6-tuple in CSCM convention.

    ``J1 = -tr(sigma)`` (compression positive, = 3P, notes sec. 1.1 [S]),
    ``J2' = s:s/2``, ``J3' = det(s)``, Lode angle
    ``beta_hat = -(1/3) asin(3 sqrt(3)/2 J3'/J2'^(3/2))`` (= +pi/6 in TXC,
    0 in TOR, -pi/6 in TXE, notes sec. 1.1 [D]).

    Returns
    -------
    J1 [Pa], sqrt(J2') [Pa], beta_hat [rad], deviator (6-tuple) [Pa].
    """
    m = (s[0] + s[1] + s[2]) / 3.0
    dev = (s[0] - m, s[1] - m, s[2] - m, s[3], s[4], s[5])
    J2, J3 = _j2_j3(dev)
    sq = math.sqrt(J2)
    r = sq
    if J2 <= 1e-200:
        # J2'^(3/2) would underflow (a 1e-110 Pa deviator at first contact)
        # and sqrt(J2') may be 0 for a non-zero deviator: the ratio is
        # scale-free, so evaluate it on the deviator over its largest component
        big = max(abs(dev[0]), abs(dev[1]), abs(dev[2]), abs(dev[3]), abs(dev[4]),
                  abs(dev[5]))
        if big == 0.0:
            return -3.0 * m, 0.0, 0.0, dev
        J2, J3 = _j2_j3((dev[0] / big, dev[1] / big, dev[2] / big, dev[3] / big,
                         dev[4] / big, dev[5] / big))
        sq = math.sqrt(J2)
        r = big * sq
    x = 1.5 * math.sqrt(3.0) * J3 / (J2 * sq)  # J2'^(3/2) without a pow()
    x = min(1.0, max(-1.0, x))
    bhat = -math.asin(x) / 3.0
    return -3.0 * m, r, bhat, dev


@njit(cache=True, error_model="numpy")
def cap_function(J1, kappa, p):
    """Elliptical cap ``Fc(J1, kappa)`` and cap location ``X(kappa)``.

    .. math::
        F_c = 1 - \\frac{(J_1 - L)^2}{(X - L)^2}\\ (J_1 > L),\\quad
        F_c = 1\\ (J_1 \\le L),\\quad L = \\max(\\kappa, \\kappa_0),\\quad
        X = L + R\\,F_f(L)

    Notes sec. 1.7 [R/S]. Returns ``(Fc, X)``; ``Fc`` clipped at 0.
    """
    L = kappa if kappa > p[P_KAPPA0] else p[P_KAPPA0]
    X = L + p[P_R] * shear_surface(L, p)
    if J1 <= L:
        return 1.0, X
    t = (J1 - L) / (X - L)
    fc = 1.0 - t * t
    return (fc if fc > 0.0 else 0.0), X


@njit(cache=True, error_model="numpy")
def cap_from_compaction(ev, p):
    """Cap location ``X`` from the plastic volume compaction ``ev``.

    Inverse of ``ev = W {1 - exp[-D1 (X - X0) - D2 (X - X0)^2]}``
    (notes sec. 1.7 [R/S]):
    ``X - X0 = [-D1 + sqrt(D1^2 - 4 D2 ln(1 - ev/W))]/(2 D2)``.
    ``ev`` is clipped to ``[0, W (1 - 1e-12)]`` (lock-up at W).
    """
    if ev <= 0.0:
        return p[P_X0]
    W = p[P_W]
    x = min(ev / W, 1.0 - 1e-12)
    lg = -math.log(1.0 - x)
    D1 = p[P_D1]
    D2 = p[P_D2]
    if D2 > 0.0:
        y = (-D1 + math.sqrt(D1 * D1 + 4.0 * D2 * lg)) / (2.0 * D2)
    else:
        y = lg / D1
    return p[P_X0] + y


@njit(cache=True, error_model="numpy")
def kappa_from_cap(X, kguess, p):
    """Solve ``X = kappa + R Ff(kappa)`` for ``kappa`` (Newton, monotone).

    Notes sec. 1.7. ``d/dkappa = 1 + R (lamda beta exp(-beta kappa) + theta) > 0``.
    """
    k = kguess
    for _ in range(50):
        g = k + p[P_R] * shear_surface(k, p) - X
        dg = 1.0 + p[P_R] * (p[P_LAMDA] * p[P_BETA] * math.exp(-p[P_BETA] * k)
                             + p[P_THETA])
        dk = g / dg
        k -= dk
        if abs(dk) <= 1e-12 * (abs(X) + 1.0):
            break
    return k


@njit(cache=True, error_model="numpy")
def surface_radius(J1, bhat, kappa, p):
    """``sqrt(J2')`` on the yield surface: ``Rub Ff sqrt(Fc)`` (0 outside
    ``[J1_apex, X]``). Yield function ``f = J2' - Rub^2 Ff^2 Fc`` (notes
    sec. 1.4 [S]; thesis eq. 5.1.1)."""
    return meridian_radius(J1, meridian(bhat, kappa, p), p)


@njit(cache=True, error_model="numpy")
def meridian(bhat, kappa, p):
    """Constants of the meridian ``F(J1)`` at fixed Lode angle and cap:
    ``(cos beta_hat, sin beta_hat, L(kappa), X(kappa))`` (see
    :func:`cap_function`), computed once per return instead of per point."""
    L = kappa if kappa > p[P_KAPPA0] else p[P_KAPPA0]
    return math.cos(bhat), math.sin(bhat), L, L + p[P_R] * shear_surface(L, p)


@njit(cache=True, error_model="numpy")
def meridian_radius(J1, m, p):
    """:func:`surface_radius` with the meridian constants ``m`` of :func:`meridian`."""
    cb, sb, L, X = m
    if J1 <= p[P_J1APEX] or J1 >= X:
        return 0.0
    ff = shear_surface(J1, p)
    if ff <= 0.0:
        return 0.0
    q1, q2 = rubin_q(J1, p)
    r = _rubin_cs(q1, q2, cb, sb) * ff
    if J1 <= L:
        return r
    t = (J1 - L) / (X - L)
    return r * math.sqrt(max(1.0 - t * t, 0.0))


@njit(cache=True, error_model="numpy")
def meridian_radius_slope(J1, m, p):
    """:func:`meridian_radius` ``F(J1)`` (the same value, bit for bit) and its
    exact slope ``F' = dF/dJ1`` [-]: the first two of
    :func:`meridian_radius_curvature` (the compiler drops the rest)."""
    F, dF, _ = meridian_radius_curvature(J1, m, p)
    return F, dF


@njit(cache=True, error_model="numpy")
def meridian_radius_curvature(J1, m, p):
    r""":func:`meridian_radius` ``F(J1)`` (the same value, bit for bit), its
    exact slope ``F'`` [-] and curvature ``F''`` [1/Pa], by the chain rule
    through :math:`F = \Re(Q_1, Q_2, \hat\beta)\, F_f\, \sqrt{F_c}`:

    .. math::
        F_f' = \lambda\beta e^{-\beta J_1} + \theta,\quad
        F_f'' = -\lambda\beta^2 e^{-\beta J_1},\quad
        Q_i' = \lambda_i\beta_i e^{-\beta_i J_1} + \theta_i,\quad
        Q_i'' = -\lambda_i\beta_i^2 e^{-\beta_i J_1}\ (J_1 > 0,\ 0\ \text{else}),

        c = \sqrt{1 - t^2},\ t = \frac{J_1 - L}{X - L}:\quad
        c' = -\frac{t}{(X - L)\,c},\quad c'' = -\frac{1}{(X - L)^2 c^3},

    and :math:`\Re`, :math:`\Re'`, :math:`\Re''` through every intermediate of
    :func:`rubin_factor` (``a``, ``b``, ``b0``, ``b1``, ``b2``; forward-mode
    differentiation to second order written out: a root ``y = (-u + sqrt(D))
    / (2 w)`` of ``w y^2 + u y + v`` has ``2 w y' = -u' + sqrt(D)' - 2 w' y``
    and ``2 w y'' = -u'' + sqrt(D)'' - 2 w'' y - 4 w' y'``). Zero outside
    ``(J1_apex, X)`` and where ``Ff <= 0``, like the value; slope
    :math:`-\infty`-like at the cap's end ``X``. Used by the return
    (:mod:`.projection`): the slope in ``dphi/dJ1``, the curvature in its
    Newton steps. Notes sec. 1.4-1.7.
    """
    cb, sb, L, X = m
    if J1 <= p[P_J1APEX] or J1 >= X:
        return 0.0, 0.0, 0.0
    e = math.exp(-p[P_BETA] * J1)
    ff = p[P_ALPHA] - p[P_LAMDA] * e + p[P_THETA] * J1
    if ff <= 0.0:
        return 0.0, 0.0, 0.0
    dff = p[P_LAMDA] * p[P_BETA] * e + p[P_THETA]
    d2ff = -p[P_LAMDA] * p[P_BETA] * p[P_BETA] * e
    if J1 <= 0.0 and J1 <= L:
        # tensile pressure, left of the cap: the Rubin ratios are held at
        # their J1 = 0 values (rubin_q: a1 - l1 exp(0) + t1 0, the same
        # bits), so the factor is a constant and F = Rub Ff: the chain
        # below would give these values with its derivatives all zero
        rub = _rubin_cs(p[P_A1] - p[P_L1], p[P_A2] - p[P_L2], cb, sb)
        return rub * ff, rub * dff, rub * d2ff
    x = J1 if J1 > 0.0 else 0.0  # (J1 <= 0 here only inside a cap with L < 0)
    e1 = math.exp(-p[P_B1] * x)
    e2 = math.exp(-p[P_B2] * x)
    q1 = p[P_A1] - p[P_L1] * e1 + p[P_T1] * x
    q2 = p[P_A2] - p[P_L2] * e2 + p[P_T2] * x
    dq1 = dq2 = d2q1 = d2q2 = 0.0
    if J1 > 0.0:
        dq1 = p[P_L1] * p[P_B1] * e1 + p[P_T1]
        dq2 = p[P_L2] * p[P_B2] * e2 + p[P_T2]
        d2q1 = -p[P_L1] * p[P_B1] * p[P_B1] * e1
        d2q2 = -p[P_L2] * p[P_B2] * p[P_B2] * e2
    # Rubin factor (as _rubin_cs) with the first and second derivative of
    # each intermediate
    a0 = 2.0 * q1 * q1 * (q2 - 1.0)
    da0 = 4.0 * q1 * dq1 * (q2 - 1.0) + 2.0 * q1 * q1 * dq2
    d2a0 = (4.0 * (dq1 * dq1 + q1 * d2q1) * (q2 - 1.0) + 8.0 * q1 * dq1 * dq2
            + 2.0 * q1 * q1 * d2q2)
    a1 = math.sqrt(3.0) * q2 + 2.0 * q1 * (q2 - 1.0)
    da1 = math.sqrt(3.0) * dq2 + 2.0 * dq1 * (q2 - 1.0) + 2.0 * q1 * dq2
    d2a1 = math.sqrt(3.0) * d2q2 + 2.0 * d2q1 * (q2 - 1.0) + 4.0 * dq1 * dq2 + 2.0 * q1 * d2q2
    a, da, d2a = _quadratic_root(q2, dq2, d2q2, a1, da1, d2a1, a0, da0, d2a0)
    u = 2.0 * q1 + a
    du = 2.0 * dq1 + da
    b = u * u - 3.0
    db = 2.0 * u * du
    d2b = 2.0 * du * du + 2.0 * u * (2.0 * d2q1 + d2a)
    b0 = -(3.0 + b - a * a) / 4.0
    db0 = -(db - 2.0 * a * da) / 4.0
    d2b0 = -(d2b - 2.0 * da * da - 2.0 * a * d2a) / 4.0
    cs = cb - a * sb
    dcs = -da * sb
    d2cs = -d2a * sb
    b1 = a * cs
    db1 = da * cs + a * dcs
    d2b1 = d2a * cs + 2.0 * da * dcs + a * d2cs
    b2 = cs * cs + b * sb * sb
    db2 = 2.0 * cs * dcs + db * sb * sb
    d2b2 = 2.0 * (dcs * dcs + cs * d2cs) + d2b * sb * sb
    rub, drub, d2rub = _quadratic_root(b2, db2, d2b2, b1, db1, d2b1, b0, db0, d2b0)
    r = rub * ff
    dr = drub * ff + rub * dff
    d2r = d2rub * ff + 2.0 * drub * dff + rub * d2ff
    if J1 <= L:
        return r, dr, d2r
    k = 1.0 / (X - L)
    t = (J1 - L) / (X - L)
    c = math.sqrt(max(1.0 - t * t, 0.0))
    if c <= 0.0:
        return 0.0, -1e300, -1e300
    ic = k / c
    dc = -t * ic
    d2c = -ic * ic / c
    return r * c, dr * c + r * dc, d2r * c + 2.0 * dr * dc + r * d2c


@njit(cache=True, error_model="numpy", inline="always")
def _quadratic_root(w, dw, d2w, u, du, d2u, v, dv, d2v):
    """The root ``y = (-u + sqrt(u^2 - 4 w v)) / (2 w)`` of ``w y^2 + u y + v``
    (discriminant clipped at 0, as :func:`_rubin_cs`) and its first two
    derivatives from those of ``w, u, v``: with ``D = u^2 - 4 w v``,
    ``s = sqrt(D)``, ``s' = D'/(2 s)``, ``s'' = (D'' - 2 s'^2)/(2 s)``,
    ``y' = (-u' + s' - 2 w' y)/(2 w)``, ``y'' = (-u'' + s'' - 2 w'' y - 4 w' y')/(2 w)``
    (``s' = s'' = 0`` where ``D <= 0``)."""
    D = u * u - 4.0 * w * v
    s = math.sqrt(max(D, 0.0))
    iw = 0.5 / w  # one division, not three, and not after the sqrt's
    ds = d2s = 0.0
    if D > 0.0:
        dD = 2.0 * u * du - 4.0 * (dw * v + w * dv)
        d2D = 2.0 * (du * du + u * d2u) - 4.0 * (d2w * v + 2.0 * dw * dv + w * d2v)
        i_s = 0.5 / s
        ds = dD * i_s
        d2s = (d2D - 2.0 * ds * ds) * i_s
    y = (-u + s) * iw
    dy = (-du + ds - 2.0 * dw * y) * iw
    d2y = (-d2u + d2s - 2.0 * d2w * y - 4.0 * dw * dy) * iw
    return y, dy, d2y


@njit(cache=True, error_model="numpy")
def yield_function(s, kappa, p):
    """``f = J2' - Rub^2 Ff^2 Fc`` of a tension-positive stress 6-tuple [Pa^2].

    Returns ``+inf``-like positive values outside ``[J1_apex, X]`` (no
    admissible state there). Notes sec. 1.4.
    """
    J1, r, bhat, dev = invariants(s)
    fc, X = cap_function(J1, kappa, p)
    if J1 < p[P_J1APEX] or J1 > X:
        return r * r + (J1 - min(max(J1, p[P_J1APEX]), X)) ** 2 + 1.0
    F = surface_radius(J1, bhat, kappa, p)
    return r * r - F * F


@njit(cache=True, error_model="numpy")
def surely_elastic(s, kappa, p):
    r"""True if the stress 6-tuple ``s`` lies inside the yield surface by a
    bound that needs neither the Lode angle nor the cap: for ``J1_apex <
    J1 <= L`` (left of the cap, ``Fc = 1``),

    .. math:: F = \Re\,F_f \ge \min(Q_1, Q_2, 1)\,F_f,

    since the Rubin factor runs between ``Q2`` (TXE), ``Q1`` (TOR) and 1
    (TXC) (tested over the fits' range), so ``sqrt(J2') < min(Q1, Q2, 1) Ff``
    (with a 1e-9 margin for round-off) is elastic. False means "check
    fully" (:func:`yield_function`), not "plastic". Saves the Lode angle,
    its cosine and sine and the cap for most elastic points. Before the
    exponentials, a cheaper bound for ``J1 >= 0``: ``sqrt(J2') <``
    ``P_R0_ELASTIC`` (:func:`elastic_radius_bound`), which implies the test
    above.
    """
    J1, r = j1_radius(s)
    L = kappa if kappa > p[P_KAPPA0] else p[P_KAPPA0]
    if not (p[P_J1APEX] < J1 <= L):
        return False
    if J1 >= 0.0 and r < p[P_R0_ELASTIC]:
        return True  # below the bound at J1 = 0 (elastic_radius_bound), no exp
    ff = shear_surface(J1, p)
    q1, q2 = rubin_q(J1, p)
    return r < min(q1, q2, 1.0) * ff * (1.0 - 1e-9)


@njit(cache=True, error_model="numpy")
def j1_radius(s):
    """``(J1, sqrt(J2'))`` of a stress 6-tuple (CSCM convention, see
    :func:`invariants`), without the Lode angle."""
    m = (s[0] + s[1] + s[2]) / 3.0
    d0, d1, d2 = s[0] - m, s[1] - m, s[2] - m
    J2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5]
    return -3.0 * m, math.sqrt(J2)


def elastic_radius_bound(p):
    r"""``sqrt(J2')`` below which a stress with ``0 <= J1 <= L`` is surely elastic
    (packed as ``P_R0_ELASTIC``; called once per material, in Python).

    Where ``Ff``, ``Q1`` and ``Q2`` do not decrease with ``J1`` (``lamda beta
    >= 0`` and ``theta >= 0`` for each: the default fits of notes sec. 2.2 up
    to about fc = 60 MPa; above, their ``Q1``, ``Q2`` decrease),
    :func:`surely_elastic`'s bound ``min(Q1, Q2, 1) Ff (1 - 1e-9)`` is smallest
    at ``J1 = 0``:

    .. math:: r_0 = 0.999\,\min(Q_1(0), Q_2(0), 1)\,F_f(0) = 0.999
              \min(\alpha_1 - \lambda_1, \alpha_2 - \lambda_2, 1)(\alpha - \lambda)

    (the 0.1 % margin covers the round-off of the functions at other ``J1``
    many times over). 0 (the bound never applies) for a surface that may
    decrease, or an ``r0`` below ``1e-6 alpha`` (a bound lost in round-off).
    """
    rising = True
    for t, lam, b in ((P_THETA, P_LAMDA, P_BETA), (P_T1, P_L1, P_B1), (P_T2, P_L2, P_B2)):
        rising = rising and p[lam] * p[b] >= 0.0 and p[t] >= 0.0
    q1, q2 = rubin_q(0.0, p)
    r0 = 0.999 * min(q1, q2, 1.0) * shear_surface(0.0, p)
    if not rising or not r0 > 1e-6 * abs(p[P_ALPHA]):
        return 0.0
    return float(r0)
