"""Total-Lagrangian SPH passes (sphdyn.parts.sph.total_lagrangian): exactness and conservation."""

import numpy as np
import pytest

from sphdyn import kernels
from sphdyn.geometry import box_lattice
from sphdyn.neighbours import build_neighbours
from sphdyn.parts.sph.total_lagrangian import (deformation_gradient, hourglass_coefficients,
                                         piola_stress, reference_gradients, tl_forces)


def _body(dim, n_side=8, dx=0.01, jitter=0.0, seed=0):
    X = box_lattice([0, 0, 0], [n_side * dx] * 3, dx, dim)
    if jitter:
        rng = np.random.default_rng(seed)
        X[:, :dim] += jitter * dx * rng.uniform(-1, 1, (X.shape[0], dim))
    n = X.shape[0]
    kid = kernels.kernel_id("cubic_spline")
    sigma = kernels.normalisation(kid, dim)
    h0 = np.full(n, 1.3 * dx)
    rho0 = np.full(n, 2000.0)
    m = rho0 * dx**dim
    vol = m / rho0
    nl = build_neighbours(X, h0, 2.0, 0.0, dim)
    fac = np.zeros(nl.idx.size, dtype=np.float32)
    w = np.zeros(nl.idx.size)
    B0 = np.zeros((n, 3, 3))
    gsum = np.zeros((n, 3))
    reference_gradients(np.arange(X.shape[0]), X, h0, vol, nl.offsets, nl.idx, kid, sigma, dim,
                        1.0, fac, w, B0, gsum)
    return dict(X=X, n=n, dim=dim, m=m, rho0=rho0, vol=vol, nl=nl, w=w, B0=B0, fac=fac,
                gsum=gsum)


def _Q(b, P):
    """V P B per particle, as piola_stress computes it."""
    return b["vol"][:, None, None] * P @ b["B0"]


def _linear_map(dim, seed=1, scale=0.2):
    A = np.eye(3) + scale * np.random.default_rng(seed).normal(size=(3, 3))
    if dim == 2:
        A[2, :] = A[:, 2] = 0.0
        A[2, 2] = 1.0
    return A


def _F(b, x, v, with_inverse=False):
    F = np.zeros((b["n"], 3, 3))
    Finv = np.zeros((b["n"], 3, 3))
    L = np.zeros((b["n"], 3, 3))
    nl = b["nl"]
    deformation_gradient(np.arange(b["n"]), x, v, b["X"], b["vol"], nl.offsets, nl.idx,
                         b["fac"], b["B0"], b["dim"], F, Finv, L)
    return (F, L, Finv) if with_inverse else (F, L)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("jitter", [0.0, 0.3])
def test_deformation_and_velocity_gradient_exact_for_linear_motion(dim, jitter):
    # x = A X + b, v = Adot X: the corrected reference gradients give F = A
    # and L = Adot A^-1 at every particle, surface included (round-off, 1e-9).
    b = _body(dim, n_side=8 if dim == 2 else 6, jitter=jitter)
    A = _linear_map(dim)
    Adot = _linear_map(dim, seed=2) - np.eye(3)
    if dim == 2:
        Adot[2, 2] = 0.0
    x = b["X"] @ A.T + 0.3
    v = b["X"] @ Adot.T
    F, L = _F(b, x, v)
    assert np.abs(F - A).max() < 1e-9
    assert np.abs(L - Adot @ np.linalg.inv(A)).max() < 1e-9


def test_rigid_rotation_gives_orthogonal_F_and_skew_L():
    b = _body(2)
    th = 0.7
    R = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
    omega = 3.0
    W = np.array([[0, -omega, 0], [omega, 0, 0], [0, 0, 0]])
    x = b["X"] @ R.T
    v = x @ W.T
    F, L = _F(b, x, v)
    assert np.abs(F - R).max() < 1e-9
    assert np.abs(L - W).max() < 1e-9  # no strain rate under rigid rotation


def test_piola_stress_definition():
    rng = np.random.default_rng(5)
    F = np.eye(3) + 0.1 * rng.normal(size=(4, 3, 3))
    s = rng.normal(size=(4, 3, 3))
    sig = s + s.transpose(0, 2, 1)
    P = np.zeros_like(F)
    Q = np.zeros_like(F)
    vol = rng.uniform(1.0, 2.0, 4)
    B = np.eye(3) + 0.1 * rng.normal(size=(4, 3, 3))
    piola_stress(np.arange(4), F, np.linalg.inv(F), sig, vol, B, P, Q)
    for k in range(4):
        ref = np.linalg.det(F[k]) * sig[k] @ np.linalg.inv(F[k]).T
        assert np.allclose(P[k], ref, rtol=1e-12, atol=1e-12)
        assert np.allclose(Q[k], vol[k] * ref @ B[k], rtol=1e-12, atol=1e-12)


def _acc(b, x, P, F, hg=0.0, young=3e10, v=None, av=0.0, heat=None):
    n = b["n"]
    a = np.zeros((n, 3))
    nl = b["nl"]
    v = np.zeros((n, 3)) if v is None else v
    dedt = np.zeros(n) if heat is None else heat
    hgk = np.zeros(b["w"].size, dtype=np.float32)
    hourglass_coefficients(np.arange(n), b["X"], b["vol"], nl.offsets, nl.idx, b["w"],
                           np.full(n, young), hg, hgk)
    tl_forces(np.arange(n), (x, v, b["X"]),
              (b["m"], b["rho0"], b["rho0"], np.full(n, 3000.0), np.full(n, 1.3 * 0.01),
               b["vol"]), (nl.offsets, nl.idx, b["fac"], hgk),
              (P, _Q(b, P), b["B0"], F, b["gsum"]), b["dim"], (av, av, 1.0), a, dedt)
    return a


@pytest.mark.parametrize("dim", [2, 3])
def test_momentum_conserved_with_hourglass_control(dim):
    # Stress and hourglass pair forces are antisymmetric: sum m a = 0 to
    # round-off (1e-12 of sum m |a|) for random stresses and a distorted cloud.
    b = _body(dim, n_side=7 if dim == 2 else 5, jitter=0.2, seed=3)
    rng = np.random.default_rng(7)
    x = b["X"] + 0.002 * rng.normal(size=b["X"].shape)
    if dim == 2:
        x[:, 2] = 0.0
    F, _, Finv = _F(b, x, np.zeros_like(x), with_inverse=True)
    s = rng.normal(size=(b["n"], 3, 3)) * 1e6
    sig = s + s.transpose(0, 2, 1)
    if dim == 2:
        sig[:, 2, :2] = sig[:, :2, 2] = 0.0
    P = np.zeros_like(F)
    piola_stress(np.arange(b["n"]), F, Finv, sig, b["vol"], b["B0"], P, np.zeros_like(P))
    a = _acc(b, x, P, F, hg=20.0)
    total = (b["m"][:, None] * a).sum(axis=0)
    assert np.abs(total).max() < 1e-12 * (b["m"][:, None] * np.abs(a)).sum()


def test_hourglass_force_vanishes_for_linear_deformation_and_restores_a_kink():
    b = _body(2, n_side=10)
    A = _linear_map(2)
    x = b["X"] @ A.T
    F, _ = _F(b, x, np.zeros_like(x))
    zero = np.zeros_like(F)
    a_lin = _acc(b, x, zero, F, hg=20.0)
    # scale: the force on a particle displaced by 1 % of dx (below)
    k = b["n"] // 2 + 5
    x2 = x.copy()
    x2[k, 0] += 1e-4
    F2, _ = _F(b, x2, np.zeros_like(x2))
    a_kink = _acc(b, x2, zero, F2, hg=20.0)
    assert np.abs(a_lin).max() < 1e-8 * np.abs(a_kink).max()
    assert a_kink[k, 0] < 0.0  # pushed back towards its place


def test_uniform_stress_gives_zero_interior_force():
    # Constant P: interior particles (two supports from the surface, where
    # all neighbours have B = I-like symmetric neighbourhoods) feel nothing.
    b = _body(2, n_side=16)
    F = np.broadcast_to(np.eye(3), (b["n"], 3, 3)).copy()
    P = np.broadcast_to(np.diag([2e6, -1e6, 0.5e6]), (b["n"], 3, 3)).copy()
    a = _acc(b, b["X"], P, F)
    X = b["X"]
    inner = np.all((X[:, :2] > 5.3 * 0.01) & (X[:, :2] < 16 * 0.01 - 5.3 * 0.01), axis=1)
    assert inner.sum() > 0
    scale = 2e6 / (2000.0 * 0.01)
    assert np.abs(a[inner]).max() < 1e-9 * scale
    assert np.abs(a).max() > 0.1 * scale


def test_same_body_pairs_keeps_only_pairs_inside_each_body():
    from sphdyn.neighbours import brute_force_neighbours
    from sphdyn.parts.sph.tl_scheme import same_body_pairs

    rng = np.random.default_rng(2)
    x = rng.uniform(0, 1, (200, 3))
    x[:, 2] = 0
    body = (x[:, 0] > 0.5).astype(np.int32)
    h = np.full(200, 0.05)
    off, idx = brute_force_neighbours(x, h, 2.0, 0.0, 2)
    o2, i2 = same_body_pairs(off, idx, body)
    for i in range(200):
        row = idx[off[i]:off[i + 1]]
        assert np.array_equal(i2[o2[i]:o2[i + 1]], row[body[row] == body[i]])


def _disordered_state(dim, seed=11):
    b = _body(dim, n_side=7 if dim == 2 else 5, jitter=0.2, seed=3)
    rng = np.random.default_rng(seed)
    x = b["X"] + 0.002 * rng.normal(size=b["X"].shape)
    v = rng.normal(size=b["X"].shape)
    if dim == 2:
        x[:, 2] = 0.0
        v[:, 2] = 0.0
    F, _, Finv = _F(b, x, v, with_inverse=True)
    return b, x, v, F


@pytest.mark.parametrize("dim", [2, 3])
def test_viscosity_and_hourglass_power_is_booked_as_heat(dim):
    # With P = 0 the only forces are viscous and hourglass pair forces; the
    # heating rate written to dedt_av must balance their power exactly:
    # sum_i m_i (a_i . v_i + dedt_i) = 0 (round-off, 1e-12 of the power scale).
    b, x, v, F = _disordered_state(dim)
    heat = np.zeros(b["n"])
    a = _acc(b, x, np.zeros_like(F), F, hg=20.0, v=v, av=1.0, heat=heat)
    power = (b["m"][:, None] * a * v).sum()
    scale = (b["m"][:, None] * np.abs(a * v)).sum()
    assert scale > 0
    assert abs(power + (b["m"] * heat).sum()) < 1e-12 * scale
    # viscosity alone dissipates: heat >= 0 in total
    heat_av = np.zeros(b["n"])
    _acc(b, x, np.zeros_like(F), F, hg=0.0, v=v, av=1.0, heat=heat_av)
    assert (b["m"] * heat_av).sum() > 0


@pytest.mark.parametrize("dim", [2, 3])
def test_viscous_forces_are_central(dim):
    # The viscous pair force acts along the current line of centres, so with
    # P = 0 and no hourglass term both linear and angular momentum are kept:
    # sum m a = 0 and sum x x m a = 0 (round-off, 1e-12 of sum m |x||a|).
    b, x, v, F = _disordered_state(dim)
    a = _acc(b, x, np.zeros_like(F), F, hg=0.0, v=v, av=1.0)
    ma = b["m"][:, None] * a
    scale = (b["m"] * np.linalg.norm(x, axis=1) * np.linalg.norm(a, axis=1)).sum()
    assert np.abs(ma.sum(axis=0)).max() < 1e-12 * scale
    assert np.abs(np.cross(x, ma).sum(axis=0)).max() < 1e-12 * scale


def test_passes_write_only_their_rows():
    # Mixed models run the TL passes on the TL particles only: rows outside
    # ``rows`` keep whatever the updated-Lagrangian passes wrote there.
    b, x, v, F = _disordered_state(2)
    n = b["n"]
    rows = np.arange(0, n, 2)
    nl = b["nl"]
    a = np.full((n, 3), 7.0)
    heat = np.full(n, 7.0)
    P = np.ones((n, 3, 3))
    hgk = np.zeros(b["w"].size, dtype=np.float32)
    hourglass_coefficients(np.arange(n), b["X"], b["vol"], nl.offsets, nl.idx, b["w"],
                           np.full(n, 3e10), 20.0, hgk)
    tl_forces(rows, (x, v, b["X"]),
              (b["m"], b["rho0"], b["rho0"], np.full(n, 3000.0), np.full(n, 0.013), b["vol"]),
              (nl.offsets, nl.idx, b["fac"], hgk), (P, _Q(b, P), b["B0"], F, b["gsum"]), 2,
              (1.0, 1.0, 1.0), a, heat)
    odd = np.arange(1, n, 2)
    assert np.all(a[odd] == 7.0) and np.all(heat[odd] == 7.0)
    assert np.all(a[rows] != 7.0)
    L = np.full((n, 3, 3), 7.0)
    Fd = np.full((n, 3, 3), 7.0)
    deformation_gradient(rows, x, v, b["X"], b["vol"], nl.offsets, nl.idx, b["fac"],
                         b["B0"], 2, Fd, np.zeros((n, 3, 3)), L)
    assert np.all(L[odd] == 7.0) and np.all(Fd[odd] == 7.0)
    assert np.abs(Fd[rows, 2, 2] - 1.0).max() == 0.0


@pytest.mark.parametrize("approach", [True, False])
def test_pair_viscosity_and_hourglass_match_their_formulas(approach):
    # Two particles, P = 0, F = I: tl_forces evaluates viscosity and
    # hourglass with one shared division (_viscous_hourglass); compare with
    # the formulas written out (docstring of tl_forces, Monaghan 1992 and
    # Ganzenmueller 2015). Round-off only: 1e-12 relative. A separating pair
    # has no viscous force.
    X = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0]])
    x = X + np.array([[0.0, 0.0, 0.0], [-0.1e-3, 0.05e-3, 0.0]])
    sgn = 1.0 if approach else -1.0
    v = np.array([[sgn * 3.0, 1.0, 0.0], [-sgn * 2.0, 0.0, 0.0]])
    m = np.array([2.0, 3.0])
    rho = np.array([2400.0, 2600.0])
    c = np.array([3000.0, 3500.0])
    h0 = np.array([1.2e-3, 1.4e-3])
    fac = np.array([-5e8, -5e8], dtype=np.float32)
    hgk = np.array([-7e5, -7e5], dtype=np.float32)
    offsets, idx = np.array([0, 1, 2]), np.array([1, 0], dtype=np.int32)
    eye = np.broadcast_to(np.eye(3), (2, 3, 3)).copy()
    zero = np.zeros((2, 3, 3))
    alpha, beta, support_scale = 1.0, 2.0, 1.0
    a = np.zeros((2, 3))
    heat = np.zeros(2)
    tl_forces(np.arange(2), (x, v, X), (m, rho, rho, c, h0, m / rho), (offsets, idx, fac, hgk),
              (zero, zero, eye, eye, np.zeros((2, 3))), 2, (alpha, beta, support_scale), a,
              heat)
    d = x[0] - x[1]
    r2 = d @ d
    vx = min((v[0] - v[1]) @ d, 0.0)
    h = support_scale * 0.5 * (h0[0] + h0[1])
    mu = h * vx / (r2 + 0.01 * h * h)
    pi = (-alpha * 0.5 * (c[0] + c[1]) * mu + beta * mu**2) / (0.5 * (rho[0] + rho[1]))
    f = float(fac[0])
    a_visc = -m[1] * pi * f * d
    s = 2.0 * (X[1] - X[0]) + 2.0 * d  # (F_i + F_j) X_ij - 2 x_ij with F = I
    f_hg = float(hgk[0]) * (s @ d) / r2 * d
    expect = a_visc + f_hg / m[0]
    assert (vx < 0) == approach and np.abs(f_hg).max() > 0
    assert np.allclose(a[0], expect, rtol=1e-12, atol=1e-12 * np.abs(expect).max())
    heat0 = 0.5 * m[1] * pi * f * vx - (f_hg @ v[0]) / m[0]
    assert heat[0] == pytest.approx(heat0, rel=1e-12)


def test_hourglass_coefficients_match_their_formula():
    # hgk_ij = -(alpha/2) V_i V_j W_ij (E_i + E_j)/2 / |X_ij|^2 (docstring of
    # hourglass_coefficients, Ganzenmueller 2015) for three particles with
    # unequal volumes, Young's moduli and kernel values, for two alphas and
    # for alpha = 0 (off: exactly zero). hgk is float32: tolerance one
    # float32 rounding, 2^-23 relative (a doubled or halved factor is off by
    # 100 % or 50 %).
    X = np.array([[0.0, 0.0, 0.0], [1.1e-3, 0.2e-3, 0.0], [0.3e-3, -0.9e-3, 0.4e-3]])
    vol = np.array([1.0e-9, 1.3e-9, 0.8e-9])
    young = np.array([30e9, 45e9, 20e9])
    offsets = np.array([0, 2, 4, 6])
    idx = np.array([1, 2, 0, 2, 0, 1], dtype=np.int32)
    w = np.array([2.0e8, 1.5e8, 2.0e8, 0.7e8, 1.5e8, 0.7e8])
    rows = np.arange(3)
    for alpha in (0.0, 10.0, 3.0):
        hgk = np.full(6, 7.0, dtype=np.float32)
        hourglass_coefficients(rows, X, vol, offsets, idx, w, young, alpha, hgk)
        for i in rows:
            for k in range(offsets[i], offsets[i + 1]):
                j = idx[k]
                r2 = float((X[j] - X[i]) @ (X[j] - X[i]))
                expect = (-0.5 * alpha * vol[i] * vol[j] * w[k]
                          * 0.5 * (young[i] + young[j]) / r2)
                if alpha == 0.0:
                    assert hgk[k] == 0.0
                else:
                    assert expect < 0.0
                    assert float(hgk[k]) == pytest.approx(expect, rel=2.0**-23, abs=0.0)
    # the pair factor is symmetric, so the hourglass force is antisymmetric
    assert hgk[0] == hgk[2] and hgk[1] == hgk[4] and hgk[3] == hgk[5]
