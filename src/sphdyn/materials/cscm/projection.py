"""CSCM return to the yield surface: closest point in the energy norm.

:func:`project` (fast path with a bracketing search, falling back to
:func:`project_global`: scan, golden section and regula falsi) and the
yield-onset fraction of a stress increment (:func:`yield_fraction`).
"""

import math

from numba import njit

from .layout import P_ALPHA, P_J1APEX
from .surface import meridian, meridian_radius, meridian_radius_slope, yield_function

NSCAN = 32  # coarse scan of the projection (see project)
NGOLDEN = 30  # golden-section iterations of the projection (bracket 5e-7 of a scan cell)


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
    then regula falsi (:func:`_refine`). If no sign change is found
    before an end of the interval, or the trial is not above the meridian,
    :func:`project_global` (scan + golden section + refinement) decides.
    The two agree to the refinement tolerance (tests/test_cscm.py).

    Returns
    -------
    (J1, sqrt(J2')) of the returned point [Pa].
    """
    return project_on_meridian(J1t, rt, meridian(bhat, kappa, p), K, G, p)


@njit(cache=True, error_model="numpy")
def project_on_meridian(J1t, rt, m, K, G, p):
    """:func:`project` with the meridian constants ``m`` of :func:`meridian`.

    Besides the fast path of :func:`project` (trial above the meridian), a
    trial in tension beyond the apex (``J1t <= J1_apex``, the usual tensile
    failure) has a fast path of its own. The meridian is concave on
    ``[J1_apex, 0]`` and on ``[0, X]`` but has a convex kink at ``J1 = 0``,
    where the Rubin ratios start to vary (:func:`rubin_q`), so ``phi`` may
    have a local minimum on each piece: each piece's is found by
    :func:`_piece_minimum` and the nearer one returned.
    """
    X = m[3]
    apex = p[P_J1APEX]
    if apex < J1t < X:
        Ft, dF = meridian_radius_slope(J1t, m, p)
        if rt > Ft > 0.0:
            g0 = (Ft - rt) * dF / G  # _dphi at J1t
            if g0 == 0.0:
                return J1t, Ft
            J1 = _bracket(J1t, g0, dF, apex, X, J1t, rt, m, K, G, p)
            if J1 == J1:  # not NaN: found
                return J1, meridian_radius(J1, m, p)
    elif J1t <= apex and rt > 0.0:
        J1 = _piece_minimum(apex, min(X, 0.0) if apex < 0.0 else X, J1t, rt, m, K, G, p)
        F = meridian_radius(J1, m, p)
        if apex < 0.0 < X:
            J1b = _piece_minimum(0.0, X, J1t, rt, m, K, G, p)
            Fb = meridian_radius(J1b, m, p)
            if _phi(J1b, Fb, J1t, rt, K, G) < _phi(J1, F, J1t, rt, K, G):
                return J1b, Fb
        return J1, F
    return _project_global(J1t, rt, m, K, G, p)


@njit(cache=True, error_model="numpy")
def _piece_minimum(a, b, J1t, rt, m, K, G, p):
    """Minimiser of ``phi`` on a piece ``[a, b]`` of the meridian on which it
    is concave, for a trial left of the piece (``J1t < a``): ``dphi/dJ1``
    increases from ``a`` up to the first ``F >= rt``, and points beyond that
    are farther, so the minimiser is the root of ``dphi/dJ1`` stepping right
    from ``a`` (:func:`_bracket`), ``a`` itself if ``dphi/dJ1 >= 0`` there,
    or ``b`` if no root comes first. The ends are taken ``1e-9 (X - J1_apex)``
    inside the piece."""
    eps = 1e-9 * (m[3] - p[P_J1APEX])
    x0 = a + eps
    g0, dF = _dphi_slope(x0, J1t, rt, m, K, G, p)
    if g0 >= 0.0:
        return x0
    J1 = _bracket(x0, g0, dF, a, b, J1t, rt, m, K, G, p)
    return J1 if J1 == J1 else b - eps


@njit(cache=True, error_model="numpy")
def _bracket(x0, g0, dF, lo, hi, J1t, rt, m, K, G, p):
    """Root of ``dphi/dJ1`` beyond ``x0`` (``g0 = dphi(x0) != 0``, ``dF`` the
    meridian slope there), on the side where ``dphi`` falls, within
    ``(lo, hi)``: steps that double until the sign changes, then
    :func:`_refine`. NaN if an end comes first.

    The first step is the Newton step with ``dphi''/2 ~ 1/(9K) + F'^2/G``,
    which underestimates the curvature where ``F < rt`` and ``F'' < 0``, so
    it usually overshoots the root and brackets it at once.
    """
    sgn = 1.0 if g0 < 0.0 else -1.0
    step = abs(g0) / (1.0 / (9.0 * K) + dF * dF / G)
    step = max(step, 1e-9 * (m[3] - p[P_J1APEX]))
    gx0 = g0
    for _ in range(40):
        x1 = x0 + sgn * step
        if x1 <= lo or x1 >= hi:
            break
        g1 = _dphi(x1, J1t, rt, m, K, G, p)
        if (g1 > 0.0) != (gx0 > 0.0):
            if sgn > 0.0:
                return _refine(x0, x1, gx0, g1, J1t, rt, m, K, G, p)
            return _refine(x1, x0, g1, gx0, J1t, rt, m, K, G, p)
        x0, gx0 = x1, g1
        step *= 2.0
    return math.nan


@njit(cache=True, error_model="numpy")
def _refine(lo, hi, gl, gh, J1t, rt, m, K, G, p):
    """Root of ``dphi/dJ1`` in ``[lo, hi]`` with ``gl < 0 < gh``.

    Regula falsi with the Anderson-Bjoerck modification (Anderson & Bjoerck
    1973; Galdino 2011 compares it with Illinois): when the same end of the
    bracket is kept twice, its value is scaled by ``1 - g_new/g_old`` (by
    1/2 if that is not positive), which keeps superlinear convergence.
    Stops when the new point moves by less than ``1e-11 (|J1t| + alpha)``
    (about 1e-4 Pa) from the last, when the bracket is that narrow, or after
    60 iterations.
    """
    tol = 1e-11 * (abs(J1t) + abs(p[P_ALPHA]))
    side = 0
    mid = 0.5 * (lo + hi)
    prev = lo if gh < -gl else hi
    for _ in range(60):
        mid = (lo * gh - hi * gl) / (gh - gl)
        gm = _dphi(mid, J1t, rt, m, K, G, p)
        if gm < 0.0:
            if side == -1:
                f = 1.0 - gm / gl
                gh *= f if f > 0.0 else 0.5
            lo, gl = mid, gm
            side = -1
        elif gm > 0.0:
            if side == 1:
                f = 1.0 - gm / gh
                gl *= f if f > 0.0 else 0.5
            hi, gh = mid, gm
            side = 1
        else:
            return mid
        if hi - lo <= tol:
            return 0.5 * (lo + hi)
        if abs(mid - prev) <= tol:
            return mid
        prev = mid
    return mid


@njit(cache=True, error_model="numpy")
def project_global(J1t, rt, bhat, kappa, K, G, p):
    """:func:`project` (same arguments and result) by a global search.

    A coarse scan of ``NSCAN + 1`` points of ``phi`` over ``[J1_apex, X]``
    brackets the global minimum, ``NGOLDEN`` golden-section steps narrow the
    bracket, and regula falsi on ``dphi/dJ1 = 0`` (:func:`_refine`)
    converges.
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
        fx = meridian_radius(x, m, p)
        ph = _phi(x, fx, J1t, rt, K, G)
        if ph < phib:
            phib = ph
            best = k
    a = lo0 + max(best - 1, 0) * width
    b = lo0 + min(best + 1, NSCAN) * width
    gr = 0.5 * (math.sqrt(5.0) - 1.0)
    c = b - gr * (b - a)
    d = a + gr * (b - a)
    fcv = meridian_radius(c, m, p)
    fdv = meridian_radius(d, m, p)
    phic = _phi(c, fcv, J1t, rt, K, G)
    phid = _phi(d, fdv, J1t, rt, K, G)
    for _ in range(NGOLDEN):
        if phic < phid:
            b = d
            d = c
            phid = phic
            c = b - gr * (b - a)
            fcv = meridian_radius(c, m, p)
            phic = _phi(c, fcv, J1t, rt, K, G)
        else:
            a = c
            c = d
            phic = phid
            d = a + gr * (b - a)
            fdv = meridian_radius(d, m, p)
            phid = _phi(d, fdv, J1t, rt, K, G)
    J1 = 0.5 * (a + b)
    # The golden section locates the minimiser only to ~sqrt(eps) relative
    # (phi is flat there); refine on dphi/dJ1 = 0 (exact meridian slope)
    # inside the golden bracket by regula falsi
    # (superlinear, the bracket is kept), if the bracket holds a sign change.
    lo = max(a, p[P_J1APEX])
    hi = min(b, X)
    gl = _dphi(lo, J1t, rt, m, K, G, p)
    gh = _dphi(hi, J1t, rt, m, K, G, p)
    if gl < 0.0 < gh:
        J1 = _refine(lo, hi, gl, gh, J1t, rt, m, K, G, p)
    return J1, meridian_radius(J1, m, p)


@njit(cache=True, error_model="numpy")
def _phi(J1, F, J1t, rt, K, G):
    """The projection distance ``phi = (J1 - J1t)^2/(9K) + (F - rt)^2/G`` of the
    meridian point ``(J1, F)`` from the trial ``(J1t, rt)`` (see :func:`project`)."""
    return (J1 - J1t) ** 2 / (9.0 * K) + (F - rt) ** 2 / G


@njit(cache=True, error_model="numpy")
def _dphi_slope(J1, J1t, rt, m, K, G, p):
    """Half the derivative of ``phi`` (see :func:`project`),
    ``(J1 - J1t)/(9K) + (F - rt) F'/G``, with the exact meridian slope ``F'``
    of :func:`meridian_radius_slope`; returns it and ``F'``."""
    F, dF = meridian_radius_slope(J1, m, p)
    return (J1 - J1t) / (9.0 * K) + (F - rt) * dF / G, dF


@njit(cache=True, error_model="numpy")
def _dphi(J1, J1t, rt, m, K, G, p):
    """Half the derivative of ``phi`` (:func:`_dphi_slope` without the slope)."""
    return _dphi_slope(J1, J1t, rt, m, K, G, p)[0]


@njit(cache=True, error_model="numpy")
def yield_fraction(s0, s1, kappa, p):
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
