"""Tests of the smoothing kernels (sphdyn.kernels)."""

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad

from sphdyn import kernels as K

KIDS = list(range(len(K.KERNEL_NAMES)))
DIMS = (1, 2, 3)
SPHERE = {1: 2.0, 2: 2.0 * math.pi, 3: 4.0 * math.pi}  # measure of the unit sphere S_d
# Interior breakpoints of each piecewise shape function (q_max is added below).
KNOTS = {0: (1.0,), 1: (1.0, 2.0), 2: (), 3: (), 4: (), 5: ()}
H = 0.37  # an arbitrary smoothing length [m] so that h-scaling is exercised


def knots(kid):
    return KNOTS[kid] + (K.support(kid),)


def radial_quad(f, kid, h):
    """int_0^{q_max h} f(r) dr, split at the knots, to near machine precision."""
    edges = [0.0] + [k * h for k in knots(kid)]
    return sum(
        quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)[0]
        for a, b in zip(edges[:-1], edges[1:])
    )


# --------------------------------------------------------------------------- API


def test_ids_and_names():
    assert K.KERNEL_IDS == {
        "cubic_spline": 0,
        "quintic_spline": 1,
        "wendland_c2": 2,
        "wendland_c4": 3,
        "gaussian": 4,
        "quadratic": 5,
    }
    for name, kid in K.KERNEL_IDS.items():
        assert K.KERNEL_NAMES[kid] == name
        assert K.kernel_id(name) == kid


def test_kernel_id_rejects_unknown_name():
    with pytest.raises(ValueError) as err:
        K.kernel_id("cubic")
    for name in K.KERNEL_NAMES:
        assert name in str(err.value)


def test_bad_id_and_dim_rejected():
    with pytest.raises(ValueError):
        K.support(6)
    with pytest.raises(ValueError):
        K.normalisation(0, 4)
    with pytest.raises(ValueError):
        K.normalisation(-1, 2)
    # compiled functions return NaN for an unknown id (raising inside them
    # would block inlining in the hot loops); the Python entry points raise.
    assert np.isnan(K.w(17, 0.5)) and np.isnan(K.dwdq_over_q(17, 0.5))


@pytest.mark.parametrize("kid", KIDS)
def test_support_nb_matches_support(kid):
    assert K.support_nb(kid) == K.support(kid)


# ---------------------------------------------------------------- moments


@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("kid", KIDS)
def test_zeroth_moment(kid, dim):
    """S_d int_0^R W(r) r^(d-1) dr = 1."""
    sig = K.normalisation(kid, dim)
    m0 = SPHERE[dim] * radial_quad(
        lambda r: K.kernel_value(kid, sig, dim, r, H) * r ** (dim - 1), kid, H
    )
    # Tolerance 1e-8 relative: quad on each smooth piece converges to ~1e-13,
    # so 1e-8 leaves margin for rounding while still catching the smallest
    # known wrong published constant (quintic 3D 3/(359 pi), off by 3e-3).
    assert m0 == pytest.approx(1.0, rel=1e-8, abs=0.0)


@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("kid", KIDS)
def test_gradient_moment(kid, dim):
    """int (x_j - x_i) (x) grad_i W(x_i - x_j) dV_j = I  (sign convention).

    With grad_i W = F (x_i - x_j) the integrand is -F r (x) r, whose angular
    average is -(F r^2 / d) I, so the diagonal is
    -(S_d/d) int_0^R F r^(d+1) dr = 1 - S_d sigma w(q_max^-) q_max^d / d
    (integration by parts). The boundary term is zero for kernels that vanish
    at q_max; for the truncated Gaussian it is the surface delta of the
    truncation that grad W omits (~1e-3), so the expectation includes it.
    """
    sig = K.normalisation(kid, dim)
    qmax = K.support(kid)
    diag = -SPHERE[dim] / dim * radial_quad(
        lambda r: K.grad_factor(kid, sig, dim, r, H) * r ** (dim + 1), kid, H
    )
    w_edge = K.w(kid, np.nextafter(qmax, 0.0))
    expected = 1.0 - SPHERE[dim] * sig * w_edge * qmax**dim / dim
    if kid != K.kernel_id("gaussian"):
        assert w_edge == pytest.approx(0.0, abs=1e-12)
    # Tolerance 1e-8: same quadrature accuracy argument as the zeroth moment.
    assert diag == pytest.approx(expected, rel=1e-8, abs=0.0)


def lattice_sums(kid, dim, x, h, dx=1.0):
    """Zeroth, first and gradient moments as SPH sums over a unit lattice."""
    sig = K.normalisation(kid, dim)
    n = int(math.ceil(K.support(kid) * h / dx)) + 1
    axis = dx * np.arange(-n, n + 1, dtype=float)
    vol = dx**dim
    s0, s1, g = 0.0, np.zeros(dim), np.zeros((dim, dim))
    for xj in itertools.product(axis, repeat=dim):
        xij = x - np.array(xj)
        r = math.sqrt(xij @ xij)
        wv = K.kernel_value(kid, sig, dim, r, h)
        s0 += vol * wv
        s1 += vol * wv * (-xij)
        g += vol * np.outer(-xij, K.grad_factor(kid, sig, dim, r, h) * xij)
    return s0, s1, g


@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("kid", KIDS)
def test_lattice_moments(kid, dim):
    """Regular lattice, h = 1.5 dx: sum V W ~ 1, sum V W (x_j - x) ~ 0,
    sum V (x_j - x) (x) grad W ~ I, at a node and at an off-node point."""
    h = 1.5
    # Tolerances: these sums are a quadrature of the continuous moments and
    # carry a discretisation error that depends on the kernel's smoothness.
    # Measured at h/dx = 1.5: zeroth <= 6e-3, first <= 2e-3 h, gradient
    # <= 1.5e-2 for the smooth kernels; the quadratic kernel has a cusp at
    # q = 0 and is far less accurate (5.6e-2, 9e-3 h, 0.11).  The bounds
    # below leave ~2x margin yet reject any wrong normalisation or a sign /
    # factor error in grad_factor, which are O(1).
    quadratic = kid == K.kernel_id("quadratic")
    tol0, tol1, tolg = (0.1, 2e-2, 0.2) if quadratic else (1e-2, 5e-3, 3e-2)
    for x in (np.zeros(dim), np.array([0.31, 0.17, 0.43])[:dim]):
        s0, s1, g = lattice_sums(kid, dim, x, h)
        assert abs(s0 - 1.0) < tol0
        assert np.abs(s1).max() < tol1 * h
        assert np.abs(g - np.eye(dim)).max() < tolg


# ------------------------------------------------------------- derivatives


def q_grid(kid, n=97, away=5e-4):
    """q values over (0, q_max + 0.5], avoiding the knots by `away`,
    plus points just either side of each knot."""
    qs = np.linspace(0.01, K.support(kid) + 0.5, n)
    ks = np.array(knots(kid))
    qs = qs[np.min(np.abs(qs[:, None] - ks[None, :]), axis=1) > away]
    near = [k + s * 1e-3 for k in ks for s in (-1.0, 1.0)]
    return np.concatenate([qs, near])


@pytest.mark.parametrize("kid", KIDS)
def test_derivatives_vs_finite_differences(kid):
    e = 1e-6
    qs = q_grid(kid)
    for f, df in ((K.w, K.dwdq), (K.dwdq, K.d2wdq2)):
        exact = np.array([df(kid, q) for q in qs])
        fd = np.array([(f(kid, q + e) - f(kid, q - e)) / (2 * e) for q in qs])
        scale = max(1.0, np.abs(exact).max())
        # Central differences with step 1e-6 on a stencil that never crosses a
        # knot: truncation ~ e^2 |f'''| / 6 <~ 1e-9 and rounding ~ 1e-16 *
        # max|f| / e <~ 1e-8 (quintic, |w| <= 66), so 1e-6 * scale bounds the
        # error with margin while any wrong coefficient gives O(1e-1) or more.
        np.testing.assert_allclose(fd, exact, rtol=0.0, atol=1e-6 * scale)


@pytest.mark.parametrize("kid", KIDS)
def test_zero_beyond_support(kid):
    qmax = K.support(kid)
    for q in (qmax, qmax + 1e-12, qmax + 0.3, 10.0, 1e6):
        # Exact zeros: the functions branch to a literal 0.0 outside support.
        assert K.w(kid, q) == 0.0
        assert K.dwdq(kid, q) == 0.0
        assert K.d2wdq2(kid, q) == 0.0
        assert K.dwdq_over_q(kid, q) == 0.0
    for q in (qmax + 1e-9, qmax + 0.3, 10.0):  # r/h rounds, so stay clear of q_max
        assert K.kernel_value(kid, 1.0, 3, q * H, H) == 0.0


def jump(f, kid, k, d=1e-10):
    return f(kid, k * (1.0 + d)) - f(kid, k * (1.0 - d))


@pytest.mark.parametrize("kid", KIDS)
def test_continuity_at_knots(kid):
    # Across [k(1-1e-10), k(1+1e-10)] a continuous function with |f'| < 1e3
    # moves by < 1e-6; a genuine jump is >= 1e-4 (the Gaussian's e^-9), so an
    # absolute tolerance of 1e-6 separates the two cases.
    gaussian = kid == K.kernel_id("gaussian")
    for k in knots(kid):
        edge = k == K.support(kid)
        if gaussian and edge:
            # The truncated Gaussian is discontinuous at q_max by design:
            # the jumps are exactly -w(3) and -w'(3).
            assert jump(K.w, kid, k) == pytest.approx(-math.exp(-9.0), rel=1e-6)
            assert jump(K.dwdq, kid, k) == pytest.approx(6.0 * math.exp(-9.0), rel=1e-6)
            continue
        assert abs(jump(K.w, kid, k)) < 1e-6
        assert abs(jump(K.dwdq, kid, k)) < 1e-6
        if kid != K.kernel_id("quadratic"):
            # C2 kernels (cubic w'' is C0 at q = 1 and 2; quintic and
            # Wendland are smoother).  The quadratic is only C1 at q = 2.
            assert abs(jump(K.d2wdq2, kid, k)) < 1e-6
    if kid == K.kernel_id("quadratic"):
        assert jump(K.d2wdq2, kid, 2.0) == pytest.approx(-0.375)


def test_cubic_second_derivative_sign_change():
    """Swegle boundary: cubic w'' < 0 for q < 2/3 and > 0 on (2/3, 2)."""
    kid = K.kernel_id("cubic_spline")
    below = np.linspace(0.0, 2.0 / 3.0, 50, endpoint=False)
    above = np.linspace(2.0 / 3.0, 2.0, 50)[1:-1]
    assert all(K.d2wdq2(kid, q) < 0.0 for q in below)
    assert all(K.d2wdq2(kid, q) > 0.0 for q in above)
    # Root located to rounding (w'' = 18 q - 12 has slope 18).
    assert abs(K.d2wdq2(kid, 2.0 / 3.0)) < 1e-13


# --------------------------------------------------------------- grad_factor


@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("kid", KIDS)
def test_grad_factor_at_origin(kid, dim):
    sig = K.normalisation(kid, dim)
    f0 = K.grad_factor(kid, sig, dim, 0.0, H)
    assert math.isfinite(f0)
    if kid == K.kernel_id("quadratic"):
        # Cone at r = 0: F -> -inf but |grad W| = |F| r -> 3/4 sigma / h^(d+1);
        # F(0) = 0 gives the zero self-gradient.  1e-6: |F r| deviates by
        # O(q) = O(1e-8) at q = 1e-8.
        assert f0 == 0.0
        r = 1e-8 * H
        fr = K.grad_factor(kid, sig, dim, r, H) * r
        assert fr == pytest.approx(-0.75 * sig / H ** (dim + 1), rel=1e-6)
        return
    # Limit F(0) = W''(0) for kernels with w'(0) = 0.
    assert K.dwdq(kid, 0.0) == 0.0
    assert f0 == pytest.approx(K.second_derivative(kid, sig, dim, 0.0, H), rel=1e-14)
    # Approaching the origin must not lose accuracy (no cancellation in w'/q):
    # F(q) - F(0) = O(q), so at q = 1e-13 the relative change is ~1e-12.
    assert K.grad_factor(kid, sig, dim, 1e-13 * H, H) == pytest.approx(f0, rel=1e-10)


@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("kid", KIDS)
def test_grad_factor_and_second_derivative_vs_fd(kid, dim):
    sig = K.normalisation(kid, dim)
    e = 1e-6 * H  # first difference
    e2 = 1e-4 * H  # second difference (larger: rounding grows like 1/e^2)
    rs = q_grid(kid, n=41) * H
    scale_w = sig / H ** (dim + 1)  # typical size of dW/dr
    scale_ww = sig / H ** (dim + 2)  # typical size of d2W/dr2
    for r in rs:
        def W(s):
            return K.kernel_value(kid, sig, dim, s, H)

        dWdr = (W(r + e) - W(r - e)) / (2 * e)
        d2Wdr2 = (W(r + e2) - 2 * W(r) + W(r - e2)) / e2**2
        # dW/dr: same error budget as the shape-function test, in units of
        # sigma/h^(d+1), with 1e-6 * max|w'| (<= 1e2) -> 1e-4.
        assert K.grad_factor(kid, sig, dim, r, H) * r == pytest.approx(
            dWdr, abs=1e-4 * scale_w
        )
        # Second difference with step 1e-4 h (stencil never crosses a knot):
        # truncation (e2/h)^2 |w''''| / 12 <~ 2e-5 and rounding
        # ~ 4e-16 |w| / (e2/h)^2 <~ 3e-6 (|w| <= 66, |w''''| <= 2e3), so 1e-3
        # of sigma/h^(d+2) holds with margin; a wrong w'' is off by O(1).
        assert K.second_derivative(kid, sig, dim, r, H) == pytest.approx(
            d2Wdr2, abs=1e-3 * scale_ww
        )


def test_kernel_context_holds_the_kernel_as_one_thing():
    # cubic spline: q_max = 2, so kappa = 1.5 gives a support of 3 h
    k = K.KernelContext.named("cubic_spline", 3, 1.5)
    assert k.kid == K.kernel_id("cubic_spline") and k.dim == 3
    assert k.sigma == K.normalisation(k.kid, 3)  # its value is tested above
    assert k.radius_factor == 3.0 and k.support_scale == 1.5
    with pytest.raises(ValueError, match="unknown kernel"):
        K.KernelContext.named("bogus", 3, 1.0)


def test_the_deck_check_and_the_parts_take_one_support_radius():
    # q_max kappa: the quintic spline reaches 3 h (Morris 1996), the Wendland C2
    # 2 h; the deck's checks (checks.size.support_radius) and the kernel
    # context of the parts give the same radius from kernels.radius_factor
    from sphdyn.checks.size import support_radius
    from sphdyn.deck.sections.sph import Sph

    assert K.radius_factor(K.kernel_id("quintic_spline"), 1.2) == pytest.approx(3.6)
    assert K.radius_factor(K.kernel_id("wendland_c2"), 1.5) == pytest.approx(3.0)
    for name in K.KERNEL_NAMES:
        sph = Sph(kernel=name, support_scale=1.3)
        assert support_radius(sph) == K.KernelContext.named(name, 2, 1.3).radius_factor
