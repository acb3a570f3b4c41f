"""CSCM return to the yield surface: closest point in the energy norm.

:func:`project` (fast path by Newton's method or a bracketing search, falling
back to :func:`project_global`: scan, golden section and regula falsi) and the
yield-onset fraction of a stress increment (:func:`yield_fraction`).
"""

import math

from numba import njit

from .layout import P_ALPHA, P_J1APEX
from .surface import (meridian, meridian_radius, meridian_radius_curvature,
                      meridian_radius_slope, yield_function)

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
    point, so the minimiser is the unique root of ``dphi/dJ1``, found by
    Newton's method from ``J1t`` (:func:`_newton`) or, should a Newton step
    leave the interval before the root is bracketed, by stepping away from
    ``J1t`` (doubling steps) until the sign changes, then regula falsi
    (:func:`_refine`). If no sign change is found
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
    return project_from_trial(J1t, rt, meridian_radius_curvature(J1t, m, p), m, K, G, p)


@njit(cache=True, error_model="numpy")
def project_from_trial(J1t, rt, Ft_slopes, m, K, G, p):
    """:func:`project_on_meridian` given the meridian's value, slope and
    curvature at the trial's ``J1t`` (``Ft_slopes =
    meridian_radius_curvature(J1t, m, p)``), which the caller's yield check
    has computed (:func:`~sphdyn.materials.cscm.point.cscm_point`): one
    meridian evaluation fewer per return."""
    X = m[3]
    apex = p[P_J1APEX]
    kink = apex < 0.0 < X  # the meridian's convex kink at J1 = 0 lies inside
    if apex < J1t < X:
        Ft, dF, d2F = Ft_slopes
        g0, gp0 = _dphi_terms(J1t, J1t, rt, Ft, dF, d2F, K, G)
        if rt > Ft > 0.0:
            if g0 == 0.0:
                return J1t, Ft
            # Newton on the trial's concave piece of the meridian
            lo, hi = apex, X
            if kink:
                lo, hi = (apex, 0.0) if J1t < 0.0 else (0.0, X)
            J1, F = _newton(J1t, g0, gp0, Ft, lo, hi, J1t, rt, m, K, G, p)
            if kink and J1t < 0.0:
                # the piece right of the kink may hold a nearer minimum (and
                # holds the only one if Newton ran into the kink)
                J1b, Fb = _piece_minimum(0.0, X, J1t, rt, m, K, G, p)
                return _nearer(J1, F, J1b, Fb, J1t, rt, K, G)
            if J1 == J1:  # not NaN: converged
                return J1, F
            J1 = _bracket(J1t, g0, dF, apex, X, J1t, rt, m, K, G, p)
            if J1 == J1:  # not NaN: found
                return J1, meridian_radius(J1, m, p)
    elif J1t <= apex and rt > 0.0:
        J1, F = _piece_minimum(apex, 0.0 if kink else X, J1t, rt, m, K, G, p)
        if kink:
            J1b, Fb = _piece_minimum(0.0, X, J1t, rt, m, K, G, p)
            return _nearer(J1, F, J1b, Fb, J1t, rt, K, G)
        return J1, F
    return _project_global(J1t, rt, m, K, G, p)


@njit(cache=True, error_model="numpy", inline="always")
def _nearer(J1a, Fa, J1b, Fb, J1t, rt, K, G):
    """Of two meridian points, the one nearer the trial in the energy norm
    (:func:`_phi`): the second if the first is NaN (not found) or farther."""
    if J1a != J1a or _phi(J1b, Fb, J1t, rt, K, G) < _phi(J1a, Fa, J1t, rt, K, G):
        return J1b, Fb
    return J1a, Fa


@njit(cache=True, error_model="numpy")
def _piece_minimum(a, b, J1t, rt, m, K, G, p):
    """Minimiser of ``phi`` on a piece ``[a, b]`` of the meridian on which it
    is concave, for a trial left of the piece (``J1t < a``): ``dphi/dJ1``
    increases from ``a`` up to the first ``F >= rt``, and points beyond that
    are farther, so the minimiser is the root of ``dphi/dJ1`` right of ``a``
    (:func:`_newton` from ``a``, else :func:`_bracket`), ``a`` itself if
    ``dphi/dJ1 >= 0`` there, or ``b`` if no root comes first. The ends are
    taken ``1e-9 (X - J1_apex)`` inside the piece. Returns ``(J1, F(J1))``."""
    eps = 1e-9 * (m[3] - p[P_J1APEX])
    x0 = a + eps
    g0, gp0, F0, dF = _dphi_curvature(x0, J1t, rt, m, K, G, p)
    if g0 >= 0.0:
        return x0, F0
    J1, F = _newton(x0, g0, gp0, F0, a, b, J1t, rt, m, K, G, p)
    if J1 == J1:
        return J1, F
    J1 = _bracket(x0, g0, dF, a, b, J1t, rt, m, K, G, p)
    J1 = J1 if J1 == J1 else b - eps
    return J1, meridian_radius(J1, m, p)


@njit(cache=True, error_model="numpy")
def _newton(x, g, gp, F, lo, hi, J1t, rt, m, K, G, p):
    """Root of ``dphi/dJ1`` by Newton's method from ``x`` (``g = dphi(x)/2``,
    ``gp`` its slope and ``F`` the meridian there, from
    :func:`_dphi_curvature`), within ``(lo, hi)``.

    ``x <- x - g/g'`` with the exact ``g' = 1/(9K) + (F'^2 + (F - rt) F'')/G``;
    once ``g`` has changed sign the bracket is kept and a step that would
    leave it bisects instead. Converged when a step is below
    ``tol = 1e-11 (|J1t| + alpha)`` (about 1e-4 Pa, the tolerance of
    :func:`_refine`): the current point is returned with its ``F`` (its error
    is of the order of that step, and the next one's far smaller: quadratic
    convergence), so no further evaluation. Or sooner, when the next step
    is predicted below ``tol / 100``: Newton's error falls as ``e' = C e^2``,
    and two successive steps ``s_1``, ``s_2`` (the errors before them) give
    ``C ~ s_2 / s_1^2`` and the step after as ``C s_2^2 = s_2^3 / s_1^2``;
    if that is at most ``tol / 100`` (and ``s_2 <= s_1``: converging; the
    first step, from the trial, is far from the asymptotic rate and not
    used), the step
    ``s_2`` is taken without evaluating the meridian at its end, whose ``F``
    is the second-order Taylor value ``F + F' s_2 + F'' s_2^2 / 2`` (on the
    meridian to 1e-12 of ``F``, 1e-15 typically: ``tests/test_cscm.py``). Returns
    ``(nan, nan)`` if a step
    would leave ``(lo, hi)`` or ``g' <= 0`` before a bracket is known, or after
    30 steps: the caller's bracketing search (:func:`_bracket`) decides.
    The paper's disc at step 300: 3.9 meridian evaluations per return
    (the first, at the trial, shared with the yield check; 4.7 without
    the prediction) against 9.7 with :func:`_bracket` + :func:`_refine`
    (docs/cscm.md).
    """
    tol = 1e-11 * (abs(J1t) + abs(p[P_ALPHA]))
    a, b = lo, hi  # g(a) < 0 < g(b) once found (flags), else the interval's ends
    have_a = have_b = False
    dF = d2F = 0.0  # the meridian's slope and curvature at x (not known at the start)
    last = -1.0  # the previous Newton step's length (-1: none, the first, or a bisection)
    for it in range(30):
        if g < 0.0:
            a, have_a = x, True
        elif g > 0.0:
            b, have_b = x, True
        else:
            return x, F
        dx = -g / gp if gp > 0.0 else math.nan
        if abs(dx) <= tol:  # before the bracket test: x + dx may round to x
            return x, F
        xn = x + dx
        if not a < xn < b:  # also NaN
            if not (have_a and have_b):
                return math.nan, math.nan
            xn = 0.5 * (a + b)
            if xn - a <= tol:
                return xn, meridian_radius(xn, m, p)
            last = -1.0
        else:
            step = abs(dx)
            if step <= last and step * step * step <= 0.01 * tol * last * last:
                return xn, F + dx * (dF + 0.5 * dx * d2F)  # next step predicted < tol
            last = step if it > 0 else -1.0
        x = xn
        F, dF, d2F = meridian_radius_curvature(x, m, p)
        g, gp = _dphi_terms(x, J1t, rt, F, dF, d2F, K, G)
    return math.nan, math.nan


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
def _dphi_curvature(J1, J1t, rt, m, K, G, p):
    """Half the derivative of ``phi`` (see :func:`_dphi_slope`), its slope
    ``1/(9K) + (F'^2 + (F - rt) F'')/G`` [1/Pa], the meridian ``F`` and its
    slope ``F'`` at ``J1`` (:func:`meridian_radius_curvature`)."""
    F, dF, d2F = meridian_radius_curvature(J1, m, p)
    g, gp = _dphi_terms(J1, J1t, rt, F, dF, d2F, K, G)
    return g, gp, F, dF


@njit(cache=True, error_model="numpy", inline="always")
def _dphi_terms(J1, J1t, rt, F, dF, d2F, K, G):
    """``g = (J1 - J1t)/(9K) + (F - rt) F'/G`` (half of ``dphi/dJ1``) and its
    slope ``g' = 1/(9K) + (F'^2 + (F - rt) F'')/G`` from the meridian's value,
    slope and curvature at ``J1`` (:func:`_dphi_curvature`)."""
    return ((J1 - J1t) / (9.0 * K) + (F - rt) * dF / G,
            1.0 / (9.0 * K) + (dF * dF + (F - rt) * d2F) / G)


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
