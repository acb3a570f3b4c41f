"""CSCM concrete model (Continuous Surface Cap Model, LS-DYNA MAT_159).

Re-implementation from the equations in ``cscm-notes.md`` (sections cited
as "notes sec. x", tags [V] verified / [S] secondary source / [R] recalled /
[D] derived or chosen here) and Y.D. Murray, *Users Manual for LS-DYNA
Concrete Material Model 159*, FHWA-HRT-05-062 (2007). See ``docs/cscm.md``.

Sign convention
---------------
sphdyn stresses are **tension positive**. The CSCM literature uses the
pressure invariant compression positive, ``J1 = 3P`` (notes sec. 1.1 [S]).
Inside this module ``J1`` always means the compression-positive
``J1 = -tr(sigma)``; the conversion happens in :func:`invariants`.
Plastic volumetric strain ``ev`` is likewise compaction positive.

Algorithm of one step (notes sec. 1.2-1.11)
-------------------------------------------
The undamaged ("viscoplastic") stress ``s_vp`` and the total strain are
history variables. The strain increment is split into ``n`` equal
sub-increments with ``|deps|/n <= incre`` (subincrementation, [V] text,
default ``incre`` is a choice [D], see :func:`pack_cscm`). Per sub-step:

1. elastic trial ``s_T = s_vp + K tr(de) I + 2G dev(de)``;
2. if ``f = J2 - (Rub Ff sqrt(Fc))^2 > 0`` (or ``J1`` outside the interval
   ``[J1_apex, X]`` where the surface exists) the inviscid stress ``s_P`` is
   the closest point of the surface in the energy norm
   ``dJ1^2/(9K) + d(sqrt J2)^2/G`` at fixed Lode angle (associated flow in
   the meridian plane; the Lode-angle component of the normal is neglected:
   choice [D]); the cap is held fixed during the projection and updated
   explicitly afterwards from the plastic compaction (sub-stepping keeps the
   lag small);
3. rate effects (off by default, IRATE = 0 [V]): Duvaut-Lions
   ``s_vp = (1-g) s_T + g s_P``, ``g = (dt/eta)/(1 + dt/eta)`` [R];
4. damage update (brittle/ductile logistic laws, [R]/[S]) and the damaged
   stress ``sigma = (1-d) s_vp`` [R].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .base import (
    N_COMMON,
    P_G,
    P_K,
    MaterialModel,
    ddot6,
    energy_increment,
    get_float,
    jaumann_rotate,
    load_sym6,
    p_wave_speed,
    rate_split,
    register,
    scale6,
    store_sym6,
)
from .cscm_params import PARAM_NAMES, default_parameters
from .elastic import elastic_increment

# --------------------------------------------------------------------------
# Parameter vector layout: [density, K, G] + PARAM_NAMES + extras
# --------------------------------------------------------------------------

_IX = {name: N_COMMON + k for k, name in enumerate(PARAM_NAMES)}
P_ALPHA, P_THETA, P_LAMDA, P_BETA = (_IX[n] for n in ("alpha", "theta", "lamda", "beta"))
P_A1, P_T1, P_L1, P_B1 = (_IX[n] for n in ("alpha1", "theta1", "lamda1", "beta1"))
P_A2, P_T2, P_L2, P_B2 = (_IX[n] for n in ("alpha2", "theta2", "lamda2", "beta2"))
P_R, P_X0, P_W, P_D1, P_D2 = (_IX[n] for n in ("R", "X0", "W", "D1", "D2"))
P_BB, P_DD, P_GFC, P_GFT, P_GFS = (_IX[n] for n in ("B", "D", "GFC", "GFT", "GFS"))
P_PWRC, P_PWRT, P_PMOD = (_IX[n] for n in ("pwrc", "pwrt", "pmod"))
P_ETA0C, P_NC, P_ETA0T, P_NT = (_IX[n] for n in ("eta0c", "nc", "eta0t", "nt"))
P_OVERC, P_OVERT, P_SRATE, P_REPOW = (_IX[n] for n in ("overc", "overt", "srate", "repow"))
_NEXT = N_COMMON + len(PARAM_NAMES)
P_IRATE = _NEXT          # 1.0: rate effects on
P_ERODE = _NEXT + 1      # 1.0: erosion on
P_ERODE_STRAIN = _NEXT + 2
P_RECOV = _NEXT + 3
P_INCRE = _NEXT + 4
P_DMAX_POWER = _NEXT + 5
P_KAPPA0 = _NEXT + 6     # derived: X0 = kappa0 + R Ff(kappa0)
P_J1APEX = _NEXT + 7     # derived: Ff(J1_apex) = 0, J1_apex < 0
P_LI2B = _NEXT + 8       # derived: Li2(-B)
P_RECOV_VOL = _NEXT + 9  # 1.0: RECOV option 2 (10-11), recovery needs compressive volume strain too
P_RETRACT = _NEXT + 10   # 1.0: the cap retracts with dilation (ITRETRC = 1)
P_RATE_R0 = _NEXT + 11   # 1.0: damage thresholds raised by the rate factor (with IRATE)
N_PARAMS = _NEXT + 12

HISTORY_NAMES = (
    "kappa", "plastic_vol_strain", "damage_brittle", "damage_ductile",
    "tau_t_max", "tau_c_max", "r0_brittle", "r0_ductile", "eroded",
    "strain_xx", "strain_yy", "strain_zz", "strain_xy", "strain_yz", "strain_xz",
    "sigvp_xx", "sigvp_yy", "sigvp_zz", "sigvp_xy", "sigvp_yz", "sigvp_xz",
    "strain_rate", "rate_factor", "rate_factor_max",
)
H_KAPPA, H_EV, H_DB, H_DD, H_TT, H_TC, H_R0T, H_R0C, H_ERODED = range(9)
H_EPS = 9
H_SVP = 15
H_RATE = 21
H_RF = 22
H_RFMAX = 23
NSCAN = 32  # coarse scan of the projection (see project)
NGOLDEN = 30  # golden-section iterations of the projection (bracket 5e-7 of a scan cell)
N_STRIPES = 64  # interleaved work stripes of the group kernel (load balance)
DMAX = 0.999  # maximum damage in unconfined states [R] (notes sec. 1.9)


# --------------------------------------------------------------------------
# Surfaces (J1 compression positive, Pa)
# --------------------------------------------------------------------------


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
    a = (-a1 + math.sqrt(max(a1 * a1 - 4.0 * a2 * a0, 0.0))) / (2.0 * a2)
    b = (2.0 * q1 + a) ** 2 - 3.0
    b0 = -(3.0 + b - a * a) / 4.0
    cs = cb - a * sb
    b1 = a * cs
    b2 = cs * cs + b * sb * sb
    return (-b1 + math.sqrt(max(b1 * b1 - 4.0 * b2 * b0, 0.0))) / (2.0 * b2)


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
    r = math.sqrt(J2)
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
        r = big * math.sqrt(J2)
    x = 1.5 * math.sqrt(3.0) * J3 / J2 ** 1.5
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
    return _radius(J1, meridian(bhat, kappa, p), p)


@njit(cache=True, error_model="numpy")
def meridian(bhat, kappa, p):
    """Constants of the meridian ``F(J1)`` at fixed Lode angle and cap:
    ``(cos beta_hat, sin beta_hat, L(kappa), X(kappa))`` (see
    :func:`cap_function`), computed once per return instead of per point."""
    L = kappa if kappa > p[P_KAPPA0] else p[P_KAPPA0]
    return math.cos(bhat), math.sin(bhat), L, L + p[P_R] * shear_surface(L, p)


@njit(cache=True, error_model="numpy")
def _radius(J1, m, p):
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
def _j1_radius(s):
    """``(J1, sqrt(J2'))`` of a stress 6-tuple (CSCM convention, see
    :func:`invariants`), without the Lode angle."""
    m = (s[0] + s[1] + s[2]) / 3.0
    d0, d1, d2 = s[0] - m, s[1] - m, s[2] - m
    J2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5]
    return -3.0 * m, math.sqrt(J2)


@njit(cache=True, error_model="numpy")
def project(J1t, rt, bhat, kappa, K, G, p):
    """Closest point of the yield surface to a trial point, energy norm.

    Minimises ``phi(J1) = (J1 - J1t)^2/(9K) + (F(J1) - rt)^2/G`` over
    ``J1 in [J1_apex, X]``, ``F = Rub Ff sqrt(Fc)`` at the trial Lode angle
    (associated closest-point return in the meridian plane for isotropic
    elasticity: notes sec. 1.3 [V text], choice [D]).

    Fast path (the usual plastic sub-step): the trial lies above the
    meridian, ``J1_apex < J1t < X`` and ``rt > F(J1t)``. For a concave
    meridian ``F`` (shear surface, Rubin ratios and elliptical cap are
    concave in J1), ``dphi/dJ1`` is increasing wherever ``F < rt``, and
    points beyond the first ``J1`` with ``F >= rt`` are farther than that
    point, so the minimiser is the unique root of ``dphi/dJ1`` found by
    stepping away from ``J1t`` (doubling steps) until the sign changes,
    then Illinois regula falsi (:func:`_refine`). If no sign change is found
    before an end of the interval, or the trial is not above the meridian,
    :func:`project_global` (scan + golden section + refinement) decides.
    The two agree to the refinement tolerance (tests/test_cscm.py).

    Returns
    -------
    (J1, sqrt(J2')) of the returned point [Pa].
    """
    return _project(J1t, rt, meridian(bhat, kappa, p), K, G, p)


@njit(cache=True, error_model="numpy")
def _project(J1t, rt, m, K, G, p):
    """:func:`project` with the meridian constants ``m`` of :func:`meridian`."""
    X = m[3]
    apex = p[P_J1APEX]
    if apex < J1t < X:
        Ft = _radius(J1t, m, p)
        if rt > Ft > 0.0:
            g0, dF = _dphi_slope(J1t, J1t, rt, m, K, G, p)
            if g0 == 0.0:
                return J1t, Ft
            sgn = 1.0 if g0 < 0.0 else -1.0
            # first step: the Newton step with dphi''/2 ~ 1/(9K) + F'^2/G,
            # which underestimates the curvature where F < rt and F'' < 0,
            # so it usually overshoots the root and brackets it at once
            step = abs(g0) / (1.0 / (9.0 * K) + dF * dF / G)
            step = max(step, 1e-9 * (X - apex))
            x0, gx0 = J1t, g0
            for _ in range(40):
                x1 = J1t + sgn * step
                if x1 <= apex or x1 >= X:
                    break
                g1 = _dphi(x1, J1t, rt, m, K, G, p)
                if (g1 > 0.0) != (gx0 > 0.0):
                    if sgn > 0.0:
                        J1 = _refine(x0, x1, gx0, g1, J1t, rt, m, K, G, p)
                    else:
                        J1 = _refine(x1, x0, g1, gx0, J1t, rt, m, K, G, p)
                    return J1, _radius(J1, m, p)
                x0, gx0 = x1, g1
                step *= 2.0
    return _project_global(J1t, rt, m, K, G, p)


@njit(cache=True, error_model="numpy")
def _refine(lo, hi, gl, gh, J1t, rt, m, K, G, p):
    """Root of ``dphi/dJ1`` in ``[lo, hi]`` with ``gl < 0 < gh`` (Illinois regula falsi).

    Superlinear bracketing iteration (Dowell & Jarratt 1971); stops at a
    bracket of ``1e-11 (|J1t| + alpha)`` (about 1e-4 Pa) or after 60
    iterations.
    """
    tol = 1e-11 * (abs(J1t) + abs(p[P_ALPHA]))
    side = 0
    mid = 0.5 * (lo + hi)
    for _ in range(60):
        mid = (lo * gh - hi * gl) / (gh - gl)
        gm = _dphi(mid, J1t, rt, m, K, G, p)
        if gm < 0.0:
            lo, gl = mid, gm
            if side == -1:
                gh *= 0.5
            side = -1
        elif gm > 0.0:
            hi, gh = mid, gm
            if side == 1:
                gl *= 0.5
            side = 1
        else:
            return mid
        if hi - lo <= tol:
            return 0.5 * (lo + hi)
    return mid


@njit(cache=True, error_model="numpy")
def project_global(J1t, rt, bhat, kappa, K, G, p):
    """Closest point of the yield surface to a trial point, energy norm (global search).

    Minimises ``phi(J1) = (J1 - J1t)^2/(9K) + (F(J1) - rt)^2/G`` over
    ``J1 in [J1_apex, X]``: a coarse scan of ``NSCAN + 1`` points brackets
    the global minimum, ``NGOLDEN`` golden-section steps narrow the bracket,
    and Illinois regula falsi on ``dphi/dJ1 = 0`` (:func:`_refine`)
    converges; ``F = Rub Ff sqrt(Fc)`` at the trial Lode
    angle. For isotropic elasticity this is the associated (closest-point)
    return restricted to the meridian plane (notes sec. 1.3 [V text], choice
    [D]).

    Returns
    -------
    (J1, sqrt(J2')) of the returned point [Pa].
    """
    return _project_global(J1t, rt, meridian(bhat, kappa, p), K, G, p)


@njit(cache=True, error_model="numpy")
def _project_global(J1t, rt, m, K, G, p):
    """:func:`project_global` with the meridian constants ``m``."""
    X = m[3]
    # phi need not be unimodal on the whole interval (e.g. a trial beyond
    # the cap: local minima on the shear part and at X), so a coarse scan
    # of NSCAN + 1 points picks the bracket of the global minimum first.
    lo0 = p[P_J1APEX]
    width = (X - lo0) / NSCAN
    best = 0
    phib = 1e300
    for k in range(NSCAN + 1):
        x = lo0 + k * width
        fx = _radius(x, m, p)
        ph = (x - J1t) ** 2 / (9.0 * K) + (fx - rt) ** 2 / G
        if ph < phib:
            phib = ph
            best = k
    a = lo0 + max(best - 1, 0) * width
    b = lo0 + min(best + 1, NSCAN) * width
    gr = 0.5 * (math.sqrt(5.0) - 1.0)
    c = b - gr * (b - a)
    d = a + gr * (b - a)
    fcv = _radius(c, m, p)
    fdv = _radius(d, m, p)
    phic = (c - J1t) ** 2 / (9.0 * K) + (fcv - rt) ** 2 / G
    phid = (d - J1t) ** 2 / (9.0 * K) + (fdv - rt) ** 2 / G
    for _ in range(NGOLDEN):
        if phic < phid:
            b = d
            d = c
            phid = phic
            c = b - gr * (b - a)
            fcv = _radius(c, m, p)
            phic = (c - J1t) ** 2 / (9.0 * K) + (fcv - rt) ** 2 / G
        else:
            a = c
            c = d
            phic = phid
            d = a + gr * (b - a)
            fdv = _radius(d, m, p)
            phid = (d - J1t) ** 2 / (9.0 * K) + (fdv - rt) ** 2 / G
    J1 = 0.5 * (a + b)
    # The golden section locates the minimiser only to ~sqrt(eps) relative
    # (phi is flat there); refine on dphi/dJ1 = 0 (central difference for F')
    # inside the golden bracket by the Illinois variant of regula falsi
    # (superlinear, the bracket is kept), if the bracket holds a sign change.
    lo = max(a, p[P_J1APEX])
    hi = min(b, X)
    gl = _dphi(lo, J1t, rt, m, K, G, p)
    gh = _dphi(hi, J1t, rt, m, K, G, p)
    if gl < 0.0 < gh:
        J1 = _refine(lo, hi, gl, gh, J1t, rt, m, K, G, p)
    return J1, _radius(J1, m, p)


@njit(cache=True, error_model="numpy")
def _dphi_slope(J1, J1t, rt, m, K, G, p):
    """Half the derivative of the projection distance ``phi`` (see
    :func:`project`), ``(J1 - J1t)/(9K) + (F - rt) F'/G``, and the meridian
    slope ``F' = dF/dJ1`` (one-sided difference, step ``h = 1e-7 (|J1| +
    alpha)``, backward within ``h`` of the cap end X; the O(h F'') error
    moves the returned point by ~1e-7 of the return distance)."""
    h = 1e-7 * (abs(J1) + abs(p[P_ALPHA]))
    F = _radius(J1, m, p)
    if J1 + h < m[3]:
        dF = (_radius(J1 + h, m, p) - F) / h
    else:
        dF = (F - _radius(J1 - h, m, p)) / h
    return (J1 - J1t) / (9.0 * K) + (F - rt) * dF / G, dF


@njit(cache=True, error_model="numpy")
def _dphi(J1, J1t, rt, m, K, G, p):
    """Half the derivative of the projection distance ``phi`` (see :func:`project`)."""
    return _dphi_slope(J1, J1t, rt, m, K, G, p)[0]


@njit(cache=True, error_model="numpy")
def _yield_fraction(s0, s1, kappa, p):
    """Fraction ``a`` in [0, 1] where ``s0 + a (s1 - s0)`` reaches the yield
    surface (bisection, 50 halvings; 0 if ``s0`` is already outside)."""
    if yield_function(s0, kappa, p) > 0.0:
        return 0.0
    lo = 0.0
    hi = 1.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        sm = (s0[0] + mid * (s1[0] - s0[0]), s0[1] + mid * (s1[1] - s0[1]),
              s0[2] + mid * (s1[2] - s0[2]), s0[3] + mid * (s1[3] - s0[3]),
              s0[4] + mid * (s1[4] - s0[4]), s0[5] + mid * (s1[5] - s0[5]))
        if yield_function(sm, kappa, p) > 0.0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


# --------------------------------------------------------------------------
# Damage
# --------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def transition(J1, r, pwr):
    """``trans = (|J1| / sqrt(3 J2'))^pwr`` clipped to [0, 1] (notes sec. 1.10 [R]).

    1 in uniaxial stress, 0 in pure shear; 1 if ``J2' = 0``.
    """
    if r <= 0.0:
        return 1.0
    x = abs(J1) / (math.sqrt(3.0) * r)
    if x >= 1.0:
        return 1.0
    return x ** pwr


@njit(cache=True, error_model="numpy")
def brittle_softening_c(r0t, size, gf, D):
    """Brittle softening parameter ``C = r0t L (1+D) ln(1+D) / (D GF)``.

    Derived so that ``L * integral(sigma d eps)`` after the peak of a
    uniaxial tension test equals ``GF`` (notes sec. 1.10 [D]; same closed
    form in Novozhilov's CapModel.py [S]). Units 1/sqrt(Pa).
    """
    return r0t * size * (1.0 + D) * math.log(1.0 + D) / (D * gf)


@njit(cache=True, error_model="numpy")
def ductile_softening_a(r0c, size, gf, B, li2mb):
    """Ductile softening parameter ``A`` (positive root of the quadratic).

    .. math:: G_F A^2 - \\frac{4L(1+B) r_{0c}\\ln(1+B)}{B} A
              + \\frac{4L(1+B)\\,\\mathrm{Li}_2(-B)}{B} = 0

    notes sec. 1.10 [D] (uniaxial compression, perfectly plastic undamaged
    stress after the peak, ``tau_c = sqrt(fc eps/2)``). Units 1/sqrt(Pa).
    """
    bq = 4.0 * size * (1.0 + B) * r0c * math.log(1.0 + B) / B
    cq = 4.0 * size * (1.0 + B) * li2mb / B
    return (bq + math.sqrt(bq * bq - 4.0 * gf * cq)) / (2.0 * gf)


@njit(cache=True, error_model="numpy")
def logistic_damage(tau, r0, rate, shape, dmax):
    """``d = (dmax/S) [(1 + S)/(1 + S exp(-k (tau - r0))) - 1]`` for tau > r0.

    Brittle (``S = D``, ``k = C``) and ductile (``S = B``, ``k = A``) laws of
    notes sec. 1.9 [R] (same forms in Novozhilov's CapModel.py [S]).
    """
    if tau <= r0:
        return 0.0
    return dmax / shape * ((1.0 + shape) / (1.0 + shape * math.exp(-rate * (tau - r0))) - 1.0)


@njit(cache=True, error_model="numpy")
def max_principal(e):
    """Largest eigenvalue of a symmetric 6-tuple (trigonometric formula)."""
    m = (e[0] + e[1] + e[2]) / 3.0
    d0 = e[0] - m
    d1 = e[1] - m
    d2 = e[2] - m
    j2 = (0.5 * (d0 * d0 + d1 * d1 + d2 * d2)
          + e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
    if j2 <= 1e-300:
        return m
    j3 = (d0 * (d1 * d2 - e[4] * e[4]) - e[3] * (e[3] * d2 - e[4] * e[5])
          + e[5] * (e[3] * e[4] - d1 * e[5]))
    x = 1.5 * math.sqrt(3.0) * j3 / j2 ** 1.5
    x = min(1.0, max(-1.0, x))
    th = math.asin(x) / 3.0   # in [-pi/6, pi/6]; largest eigenvalue:
    return m + 2.0 * math.sqrt(j2 / 3.0) * math.cos(math.pi / 6.0 - th)


# --------------------------------------------------------------------------
# Point update
# --------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def cscm_point(h, deps, dt, p, size):
    """CSCM update of one material point (state in the history row ``h``).

    Parameters
    ----------
    h : float64[:]
        History row (:data:`HISTORY_NAMES`), in/out; holds the undamaged
        stress (already Jaumann-rotated by the caller) and the total strain.
    deps : 6-tuple
        Strain increment ``D dt`` [-].
    dt : float
        Time step [s] (rate effects only).
    p : float64[:]
        Packed parameters (SI).
    size : float
        Particle size L [m] for the fracture-energy regularisation.

    Returns
    -------
    sig : 6-tuple
        Damaged stress ``(1 - d) s_vp`` [Pa], tension positive.
    d : float
        Total damage (1 for an eroded point).
    """
    K = p[P_K]
    G = p[P_G]
    E = 9.0 * K * G / (3.0 * K + G)
    svp = (h[H_SVP], h[H_SVP + 1], h[H_SVP + 2], h[H_SVP + 3], h[H_SVP + 4], h[H_SVP + 5])
    eps = (h[H_EPS], h[H_EPS + 1], h[H_EPS + 2], h[H_EPS + 3], h[H_EPS + 4], h[H_EPS + 5])
    if h[H_ERODED] > 0.0:
        # eroded: no deviatoric and no tensile stress, mass kept; the
        # (compressive) mean stress follows the bulk modulus.
        m = (svp[0] + svp[1] + svp[2]) / 3.0 + K * (deps[0] + deps[1] + deps[2])
        m = m if m < 0.0 else 0.0
        svp = (m, m, m, 0.0, 0.0, 0.0)
        eps = (eps[0] + deps[0], eps[1] + deps[1], eps[2] + deps[2],
               eps[3] + deps[3], eps[4] + deps[4], eps[5] + deps[5])
        for k in range(6):
            h[H_SVP + k] = svp[k]
            h[H_EPS + k] = eps[k]
        return svp, 1.0

    nrm = math.sqrt(ddot6(deps, deps))
    n = 1
    if nrm > p[P_INCRE]:
        n = min(int(nrm / p[P_INCRE]) + 1, 10000)
    de = scale6(deps, 1.0 / n)
    dts = dt / n
    irate = p[P_IRATE] > 0.0
    rate = 0.0
    if dt > 0.0:
        rate = math.sqrt(2.0 / 3.0 * ddot6(deps, deps)) / dt
    h[H_RATE] = rate
    eta_t = eta_c = eta_s = 0.0
    if irate and rate > 1e-12:
        # fluidities eta_t = eta0t/rate^nt, eta_c = eta0c/rate^nc,
        # eta_s = srate eta_t (notes 1.11 [R]), constant over the step
        eta_t = p[P_ETA0T] / rate ** p[P_NT]
        eta_c = p[P_ETA0C] / rate ** p[P_NC]
        eta_s = p[P_SRATE] * eta_t
    rf = 1.0
    for _ in range(n):
        eps = (eps[0] + de[0], eps[1] + de[1], eps[2] + de[2],
               eps[3] + de[3], eps[4] + de[4], eps[5] + de[5])
        svp_old = svp
        trial = elastic_increment(svp, de, K, G)
        kappa = h[H_KAPPA]
        # yield check f = J2' - F^2 <= tol (as yield_function, with the
        # invariants and meridian constants reused by the return)
        J1t, rt, bhat, dev = invariants(trial)
        mer = meridian(bhat, kappa, p)
        ft = _radius(J1t, mer, p)
        if (p[P_J1APEX] <= J1t <= mer[3]
                and rt * rt - ft * ft <= 1e-12 * (p[P_ALPHA] ** 2)):
            svp = trial
        else:
            J1p, rp = _project(J1t, rt, mer, K, G, p)
            fac = rp / rt if rt > 0.0 else 0.0
            mp = -J1p / 3.0
            sP = (fac * dev[0] + mp, fac * dev[1] + mp, fac * dev[2] + mp,
                  fac * dev[3], fac * dev[4], fac * dev[5])
            gam = 1.0
            over = 0.0
            if irate and rate > 1e-12:
                # Duvaut-Lions fluidity, interpolated with trans (notes 1.11 [R])
                # (eta_t, eta_c, eta_s depend on the step's rate only)
                if J1t < 0.0:
                    tr = transition(J1t, rt, p[P_PWRT])
                    eta = eta_s + tr * (eta_t - eta_s)
                    over = p[P_OVERT]
                else:
                    tr = transition(J1t, rt, p[P_PWRC])
                    eta = eta_s + tr * (eta_c - eta_s)
                    over = p[P_OVERC]
                # overstress limit E rate eta <= OVER (notes 1.11 [R], choice [D])
                eta_max = over / (E * rate)
                if eta > eta_max:
                    eta = eta_max
                x = dts / eta
                gam = x / (1.0 + x)
            if gam < 1.0:
                # overstress s_vp - s_P = (1 - g)(s_T - s_P); its Frobenius
                # norm (= the axial overstress in uniaxial stress) is also
                # clipped at OVER: choice [D], a hard form of the bound
                ov = (trial[0] - sP[0], trial[1] - sP[1], trial[2] - sP[2],
                      trial[3] - sP[3], trial[4] - sP[4], trial[5] - sP[5])
                ovn = (1.0 - gam) * math.sqrt(ddot6(ov, ov))
                g1 = 1.0 - gam
                if ovn > over:
                    g1 *= over / ovn
                svp = (sP[0] + g1 * ov[0], sP[1] + g1 * ov[1], sP[2] + g1 * ov[2],
                       sP[3] + g1 * ov[3], sP[4] + g1 * ov[4], sP[5] + g1 * ov[5])
                J1v, rv = _j1_radius(svp)
                # dynamic-to-static strength ratio sqrt(J2'_vp / J2'_P), the
                # shear-strength ratio of the J2'-based surface: choice [D]
                # for the "dynamic/static strength" of notes sec. 1.10 (the
                # ratio of full-tensor norms was tried: it hardly rises under
                # confinement and lets ductile damage start early in the disc,
                # see docs/cscm.md)
                rf = rv / rp if rp > 0.0 and rv > rp else 1.0
            else:
                svp = sP
                J1v = J1p
            # plastic compaction (compression positive) and cap hardening:
            # X = X(ev) of the compaction law. ITRETRC = 0 (default): the cap
            # never retracts (X only grows); ITRETRC = 1: X follows ev both
            # ways, so dilation pulls the cap back, never inside X0 (notes
            # sec. 1.3/1.7 [V flag text], mechanism [R/D])
            h[H_EV] += (J1t - J1v) / (3.0 * K)
            if h[H_EV] > 0.0 or p[P_RETRACT] > 0.0:
                X = cap_from_compaction(h[H_EV], p)
                Xold = mer[3]
                if X > Xold or (p[P_RETRACT] > 0.0 and X < Xold):
                    h[H_KAPPA] = kappa_from_cap(X, kappa, p)
            # damage thresholds: the damage state variable at first yield
            # (notes sec. 1.9 [R]), evaluated at the yield-onset point inside
            # the sub-step so that it does not depend on the increment size
            if (J1v < 0.0 and h[H_R0T] <= 0.0) or (J1v >= 0.0 and h[H_R0C] <= 0.0):
                s0 = elastic_increment(svp_old, scale6(de, 0.0), K, G)
                fr = _yield_fraction(s0, trial, kappa, p)
                e_on = (eps[0] - (1.0 - fr) * de[0], eps[1] - (1.0 - fr) * de[1],
                        eps[2] - (1.0 - fr) * de[2], eps[3] - (1.0 - fr) * de[3],
                        eps[4] - (1.0 - fr) * de[4], eps[5] - (1.0 - fr) * de[5])
                s_on = (s0[0] + fr * (trial[0] - s0[0]), s0[1] + fr * (trial[1] - s0[1]),
                        s0[2] + fr * (trial[2] - s0[2]), s0[3] + fr * (trial[3] - s0[3]),
                        s0[4] + fr * (trial[4] - s0[4]), s0[5] + fr * (trial[5] - s0[5]))
                if J1v < 0.0:
                    h[H_R0T] = max(math.sqrt(E) * max_principal(e_on), 1e-30)
                else:
                    h[H_R0C] = max(math.sqrt(max(0.5 * ddot6(s_on, e_on), 0.0)), 1e-30)
        # damage evolution
        if h[H_R0T] > 0.0 or h[H_R0C] > 0.0:
            J1v, rv = _j1_radius(svp)
            gscale = rf ** p[P_REPOW] if irate else 1.0
            # rate-enhanced thresholds (choice [D]; notes sec. 1.9 [R] only
            # say that they increase with rate): r0 x the largest dynamic-to-
            # static strength ratio reached, so that damage starts at the
            # viscoplastic (dynamic) strength; never decreasing, like a
            # damage threshold. In uniaxial stress tau = rf r0 at the dynamic
            # peak for both tau_t = sqrt(E) eps and tau_c = sqrt(s:eps/2).
            rscale = 1.0
            if irate and p[P_RATE_R0] > 0.0:
                if rf > h[H_RFMAX]:
                    h[H_RFMAX] = rf
                rscale = h[H_RFMAX]
            if J1v < 0.0 and h[H_R0T] > 0.0:
                tau = math.sqrt(E) * max(max_principal(eps), 0.0)
                if tau > h[H_TT]:
                    h[H_TT] = tau
                tr = transition(J1v, rv, p[P_PWRT])
                gf = (p[P_GFS] + tr * (p[P_GFT] - p[P_GFS])) * gscale
                r0 = h[H_R0T] * rscale
                cc = brittle_softening_c(r0, size, gf, p[P_DD])
                db = logistic_damage(h[H_TT], r0, cc, p[P_DD], DMAX)
                if db > h[H_DB]:
                    h[H_DB] = db
            elif J1v >= 0.0 and h[H_R0C] > 0.0:
                tau = math.sqrt(max(0.5 * ddot6(svp, eps), 0.0))
                if tau > h[H_TC]:
                    h[H_TC] = tau
                tr = transition(J1v, rv, p[P_PWRC])
                gf = (p[P_GFS] + tr * (p[P_GFC] - p[P_GFS])) * gscale
                r0 = h[H_R0C] * rscale
                aa = ductile_softening_a(r0, size, gf, p[P_BB], p[P_LI2B])
                # maximum ductile damage vs confinement: choice [D] (formula
                # not retrieved, notes sec. 1.9): DMAX (sqrt(3 J2')/J1)^power
                ratio = math.sqrt(3.0) * rv / J1v if J1v > 0.0 else 1.0
                dmax = DMAX * (min(ratio, 1.0) ** p[P_DMAX_POWER])
                dd = logistic_damage(h[H_TC], r0, aa, p[P_BB], dmax)
                if dd > h[H_DD]:
                    h[H_DD] = dd
    h[H_RF] = rf
    for k in range(6):
        h[H_SVP + k] = svp[k]
        h[H_EPS + k] = eps[k]
    # applied damage and recovery (notes sec. 1.9 [V flag / R mechanism]):
    # brittle damage is recovered to RECOV d_b under compressive pressure
    # (option 1, RECOV 0-1) and, for option 2 (RECOV 10-11), only if the
    # volumetric strain is compressive as well
    J1v = -(svp[0] + svp[1] + svp[2])
    compressed = J1v > 0.0
    if p[P_RECOV_VOL] > 0.0 and eps[0] + eps[1] + eps[2] >= 0.0:
        compressed = False
    if compressed:
        d = max(p[P_RECOV] * h[H_DB], h[H_DD])
    else:
        d = max(h[H_DB], h[H_DD])
    # erosion (notes sec. 1.9 ERODE [V text, R reading]): d > 0.99 and max
    # principal strain > erode_strain (= ERODE - 1)
    if p[P_ERODE] > 0.0 and d > 0.99 and max_principal(eps) > p[P_ERODE_STRAIN]:
        h[H_ERODED] = 1.0
        m = (svp[0] + svp[1] + svp[2]) / 3.0
        m = m if m < 0.0 else 0.0
        for k in range(3):
            h[H_SVP + k] = m
            h[H_SVP + 3 + k] = 0.0
        return (m, m, m, 0.0, 0.0, 0.0), 1.0
    return scale6(svp, 1.0 - d), d


@njit(cache=True, error_model="numpy", parallel=True)
def cscm_update(idx, L, dt, rho, sig, e, c, damage, hist, params, size):
    """Group kernel of the CSCM model (common kernel signature).

    For each ``i`` in ``idx``: Jaumann rotation of the damaged stress (for the
    energy balance), of the stored undamaged stress and of the total strain;
    :func:`cscm_point`; energy increment; ``damage[i]`` = total damage;
    ``c[i] = sqrt((1-d)(K + 4G/3)/rho)`` with the damaged moduli (``sqrt(K/rho)``
    with the undamaged K for an eroded point, which keeps a compressive
    pressure). Shapes/units: ``base.KERNEL_SIGNATURE_DOC``.

    The particles are dealt round-robin to ``N_STRIPES`` interleaved stripes
    (stripe ``t`` takes ``idx[t], idx[t + N_STRIPES], ...``) and the stripes
    to the threads: plastic points cost ten times more than elastic ones and
    cluster in space (the contact zone), which a contiguous split of ``idx``
    would give to one thread. Each particle writes only its own rows.
    """
    n = idx.shape[0]
    for t in prange(N_STRIPES):
        for k in range(t, n, N_STRIPES):
            _update_particle(idx[k], L, dt, rho, sig, e, c, damage, hist, params, size)


@njit(cache=True, error_model="numpy")
def _update_particle(i, L, dt, rho, sig, e, c, damage, hist, params, size):
    """One particle of :func:`cscm_update`."""
    K = params[P_K]
    G = params[P_G]
    d, w = rate_split(L, i)
    s_old = jaumann_rotate(load_sym6(sig, i), w, dt)
    h = hist[i]
    svp = jaumann_rotate((h[H_SVP], h[H_SVP + 1], h[H_SVP + 2],
                          h[H_SVP + 3], h[H_SVP + 4], h[H_SVP + 5]), w, dt)
    ep = jaumann_rotate((h[H_EPS], h[H_EPS + 1], h[H_EPS + 2],
                         h[H_EPS + 3], h[H_EPS + 4], h[H_EPS + 5]), w, dt)
    for j in range(6):
        h[H_SVP + j] = svp[j]
        h[H_EPS + j] = ep[j]
    s_new, dmg = cscm_point(h, scale6(d, dt), dt, params, size[i])
    store_sym6(sig, i, s_new)
    damage[i] = dmg
    e[i] += energy_increment(s_old, s_new, d, dt, rho[i])
    if h[H_ERODED] > 0.0:
        c[i] = p_wave_speed(K, 0.0, rho[i])
    else:
        c[i] = p_wave_speed((1.0 - dmg) * K, (1.0 - dmg) * G, rho[i])


# --------------------------------------------------------------------------
# Packing
# --------------------------------------------------------------------------


def dilog_neg(B: float) -> float:
    """``Li2(-B)`` for ``B >= 0`` (dilogarithm).

    Series ``Li2(z) = sum z^k/k^2`` for ``|z| <= 1/2``; for ``B > 1/2`` the
    inversion ``Li2(-x) = -pi^2/6 - ln(x)^2/2 - Li2(-1/x)`` (x > 1) and for
    ``1/2 < B <= 1`` the Landen-free direct series (alternating, converging).
    """
    def series(z: float) -> float:
        total, term, k = 0.0, z, 1
        while abs(term) / (k * k) > 1e-17 and k < 100000:
            total += term / (k * k)
            k += 1
            term *= z
        return total

    if B <= 1.0:
        return series(-B)
    return -math.pi ** 2 / 6.0 - 0.5 * math.log(B) ** 2 - series(-1.0 / B)


def _apex(p: np.ndarray) -> float:
    """``J1 < 0`` with ``Ff(J1) = 0`` (tensile apex of the shear surface), bisection."""
    lo, hi = -1.0, 0.0
    if float(shear_surface(0.0, p)) <= 0.0:
        raise ValueError("cscm: the shear surface Ff(0) = alpha - lamda must be > 0")
    while float(shear_surface(lo, p)) > 0.0:
        lo *= 2.0
        if lo < -1e15:
            raise ValueError("cscm: the shear surface has no tensile apex")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if float(shear_surface(mid, p)) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


def cscm_parameters(values: dict) -> dict:
    """SI parameter dict of a CSCM material from deck-style values.

    Keys: ``density`` (required), ``fc`` [Pa] (default 30 MPa), ``aggregate_size``
    [m] (default 19 mm), any override of
    :func:`sphdyn.materials.cscm_params.default_parameters` (``K``, ``G``,
    ``alpha``, ..., ``repow``), and the switches ``rate_effects`` (bool,
    default False = IRATE 0), ``erode`` (bool, default False),
    ``erode_strain`` (default 0.05, i.e. ERODE = 1.05), ``recovery`` (RECOV
    in [0, 1] or [10, 11], default 0: LS-DYNA option 1 on the sign of the
    pressure, option 2 = RECOV - 10 on the signs of pressure and volume
    strain), ``cap_retraction`` (bool, ITRETRC = 1, default False),
    ``rate_thresholds`` (bool, default True: with rate effects the damage
    thresholds scale with the dynamic strength ratio, choice [D]), ``incre`` (sub-increment strain limit, default from
    the strength, see :func:`pack_cscm`), ``dmax_power`` (default 1).
    """
    fc = get_float(values, "fc", default=30e6, min_value=0.0, min_inclusive=False)
    dagg = get_float(values, "aggregate_size", default=0.019, min_value=0.0,
                     min_inclusive=False)
    over = {k: values[k] for k in ("K", "G", *PARAM_NAMES)
            if k in values and values[k] is not None}
    for k in over:
        get_float(values, k)
    out = default_parameters(fc, dagg, **over)
    if "E" in values or "nu" in values:
        raise ValueError("cscm: give K and G (or neither, for the defaults), not E/nu")
    out["density"] = get_float(values, "density", min_value=0.0, min_inclusive=False)
    out["rate_effects"] = bool(values.get("rate_effects", False))
    out["erode"] = bool(values.get("erode", False))
    out["erode_strain"] = get_float(values, "erode_strain", default=0.05, min_value=0.0)
    recov = get_float(values, "recovery", default=0.0, min_value=0.0, max_value=11.0)
    if 1.0 < recov < 10.0:
        raise ValueError(f"material parameter 'recovery' must be in [0, 1] (recovery "
                         f"on the pressure sign) or [10, 11] (pressure and volume "
                         f"strain signs, LS-DYNA RECOV option 2), got {recov}")
    out["recovery"] = recov
    out["cap_retraction"] = bool(values.get("cap_retraction", False))
    out["rate_thresholds"] = bool(values.get("rate_thresholds", True))
    out["dmax_power"] = get_float(values, "dmax_power", default=1.0, min_value=0.0)
    if values.get("incre") is not None:
        out["incre"] = get_float(values, "incre", min_value=0.0, min_inclusive=False)
    for k in ("K", "G", "R", "W", "D1", "B", "D", "GFC", "GFT", "GFS"):
        if not out[k] > 0.0:
            raise ValueError(f"cscm: parameter {k!r} must be > 0, got {out[k]}")
    return out


def pack_cscm(values: dict) -> np.ndarray:
    """Packed CSCM parameter vector from SI values (see :func:`cscm_parameters`).

    Layout ``[density, K, G] + PARAM_NAMES + [irate, erode, erode_strain,
    recovery, incre, dmax_power, kappa0, J1_apex, Li2(-B), recovery_mode,
    cap_retraction, rate_thresholds]``. The default
    sub-increment limit is ``incre = 0.25 (alpha - lamda) / (2 G)``, a quarter
    of the tensor shear strain at which the TXC surface is reached at zero
    pressure (LS-DYNA's INCRE default formula is not known, notes sec. 1.3:
    choice [D]).
    """
    v = cscm_parameters(values)
    p = np.zeros(N_PARAMS)
    p[0], p[P_K], p[P_G] = v["density"], v["K"], v["G"]
    for name in PARAM_NAMES:
        p[_IX[name]] = v[name]
    p[P_IRATE] = 1.0 if v["rate_effects"] else 0.0
    p[P_ERODE] = 1.0 if v["erode"] else 0.0
    p[P_ERODE_STRAIN] = v["erode_strain"]
    p[P_RECOV] = v["recovery"] - 10.0 if v["recovery"] >= 10.0 else v["recovery"]
    p[P_RECOV_VOL] = 1.0 if v["recovery"] >= 10.0 else 0.0
    p[P_RETRACT] = 1.0 if v["cap_retraction"] else 0.0
    p[P_RATE_R0] = 1.0 if v["rate_thresholds"] else 0.0
    p[P_DMAX_POWER] = v["dmax_power"]
    p[P_INCRE] = v.get("incre", 0.25 * (v["alpha"] - v["lamda"]) / (2.0 * v["G"]))
    p[P_J1APEX] = _apex(p)
    # kappa0 from X0 = kappa0 + R Ff(kappa0)
    p[P_KAPPA0] = -1e300
    p[P_KAPPA0] = float(kappa_from_cap(v["X0"], 0.0, p))
    if not p[P_KAPPA0] > p[P_J1APEX]:
        raise ValueError("cscm: X0 is too small (initial cap inside the tensile apex)")
    p[P_LI2B] = dilog_neg(v["B"])
    return p


def initial_history(p: np.ndarray) -> np.ndarray:
    """Initial history: ``kappa = kappa0``, everything else 0.

    An all-zero row is also a valid initial state (``kappa = 0`` acts as
    ``kappa0`` since ``L = max(kappa, kappa0)``; a damage threshold of 0 means
    "not yet reached"), so callers that do not apply this function work too.
    """
    h = np.zeros(len(HISTORY_NAMES))
    h[H_KAPPA] = p[P_KAPPA0]
    h[H_RF] = 1.0
    h[H_RFMAX] = 1.0
    return h


def kappa0(p: np.ndarray) -> float:
    """Initial cap parameter kappa0 [Pa] (J1, compression positive)."""
    return float(p[P_KAPPA0])


CSCM = register(MaterialModel(
    name="cscm",
    history_names=HISTORY_NAMES,
    pack=pack_cscm,
    update=cscm_update,
    history_init=initial_history,
))
