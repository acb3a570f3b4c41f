"""Artificial stress (Monaghan 2000; Gray, Monaghan & Swift 2001): tensor and pair force."""

import numpy as np
import pytest

from sphdyn import kernels
from sphdyn.deck import DeckError, loads_deck
from sphdyn.geometry import box_lattice
from sphdyn.neighbours import build_neighbours
from stepping import build_stepper
from sphdyn.parts.sph.artificial_stress import artificial_stress_forces, artificial_stress_tensor
from sphdyn.parts.sph.gradient import gradient_scratch, velocity_gradient

RHO = 1000.0
EPS = 0.3


def _tensor(sig, rho=RHO, eps=EPS):
    sig = np.asarray(sig, float).reshape(-1, 3, 3)
    R = np.zeros_like(sig)
    Q = np.zeros_like(sig)
    artificial_stress_tensor(sig, np.full(sig.shape[0], rho), np.full(sig.shape[0], eps), R, Q)
    return R


def _reference(sig, rho=RHO, eps=EPS):
    """Independent evaluation with numpy's eigh."""
    lam, vec = np.linalg.eigh(sig)
    r = np.where(lam > 0, -eps * lam / rho**2, 0.0)
    return (vec * r) @ vec.T


def _rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q


def test_uniaxial_tension_and_compression():
    # R'_xx = -eps sigma_xx / rho^2 in tension (Gray et al. 2001 eq. 4.8), 0 in compression
    s = 2.0e6
    R = _tensor(np.diag([s, 0.0, 0.0]))[0]
    assert np.allclose(R, np.diag([-EPS * s / RHO**2, 0, 0]), rtol=0, atol=1e-15)
    assert np.all(_tensor(np.diag([-s, -0.5 * s, 0.0])) == 0.0)
    assert np.all(_tensor(np.zeros((3, 3))) == 0.0)


def test_pure_shear_only_the_tensile_direction():
    # sigma_xy = tau: principal +tau along (1,1)/sqrt2, -tau along (1,-1)/sqrt2
    tau = 1.0e6
    sig = np.zeros((3, 3))
    sig[0, 1] = sig[1, 0] = tau
    n = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    expect = -EPS * tau / RHO**2 * np.outer(n, n)
    # Jacobi converges to round-off: tolerance 1e-12 of the magnitude
    assert np.abs(_tensor(sig)[0] - expect).max() < 1e-12 * EPS * tau / RHO**2


@pytest.mark.parametrize("seed", range(5))
def test_rotated_mixed_stress_matches_eigh(seed):
    # principal stresses of mixed sign in a random frame, incl. a repeated value
    lam = [[3e6, -1e6, 5e5], [2e6, 2e6, -4e6], [-1e6, -2e6, -3e6], [1e6, 1e6, 1e6],
           [4e6, 0.0, -1e5]][seed]
    q = _rotation(seed)
    sig = q @ np.diag(lam) @ q.T
    R = _tensor(sig)[0]
    ref = _reference(sig)
    scale = EPS * max(abs(v) for v in lam) / RHO**2
    assert np.abs(R - ref).max() < 1e-12 * scale
    assert np.allclose(R, R.T, rtol=0, atol=1e-15 * scale)
    # negative semi-definite: a repulsive (pressure-like) stress
    assert np.linalg.eigvalsh(R).max() < 1e-12 * scale


def _cloud(dim, n_side=8, dx=0.01, hfac=1.3, jitter=0.2, seed=0):
    x = box_lattice([0, 0, 0], [n_side * dx] * 3, dx, dim)
    rng = np.random.default_rng(seed)
    x[:, :dim] += jitter * dx * rng.uniform(-1, 1, (x.shape[0], dim))
    n = x.shape[0]
    kid = kernels.kernel_id("cubic_spline")
    rho = RHO * (1 + 0.1 * rng.uniform(-1, 1, n))
    m = RHO * dx**dim * (1 + 0.1 * rng.uniform(-1, 1, n))
    h = hfac * dx * (1 + 0.1 * rng.uniform(-1, 1, n))
    nl = build_neighbours(x, h, kernels.support(kid), 0.0, dim)
    F = np.zeros(nl.idx.size, dtype=np.float32)
    L = np.zeros((n, 3, 3))
    B = np.zeros((n, 3, 3))
    velocity_gradient(x, np.zeros((n, 3)), h, m, rho, nl.offsets, nl.idx,
                      np.diff(nl.offsets).astype(np.int32), kid, kernels.normalisation(kid, dim),
                      dim, 1.0, False, F, L, B, np.zeros(n, np.int32),
                      gradient_scratch(nl.offsets))
    sig = rng.normal(scale=1e6, size=(n, 3, 3))
    sig = 0.5 * (sig + sig.transpose(0, 2, 1))
    if dim == 2:
        sig[:, 2, :2] = sig[:, :2, 2] = 0.0
    return dict(x=x, m=m, rho=rho, h=h, nl=nl, kid=kid, F=F, sig=sig, dim=dim, dx=dx,
                spacing=np.full(n, dx))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("n_exp", [4.0, 2.5])
def test_momentum_conserved_to_round_off(dim, n_exp):
    # pair terms m_i m_j f^n (R_i + R_j) grad_i W_ij are antisymmetric, so
    # sum_i m_i a_i = 0 up to round-off (1e-12 of sum |m_i a_i|) on an
    # irregular cloud with unequal masses, densities and smoothing lengths
    c = _cloud(dim)
    n = c["x"].shape[0]
    R = np.zeros((n, 3, 3))
    artificial_stress_tensor(c["sig"], c["rho"], np.full(n, EPS), R, np.zeros((n, 3, 3)))
    a = np.zeros((n, 3))
    nl = c["nl"]
    artificial_stress_forces(c["x"], c["m"], c["h"], R, c["F"], nl.offsets, nl.idx,
                             c["kid"], dim, 1.0, c["spacing"], n_exp, a, np.zeros((n, 3)),
                             np.zeros(n))
    p = c["m"][:, None] * a
    scale = np.abs(p).sum()
    assert scale > 0.0
    assert np.abs(p.sum(axis=0)).max() < 1e-12 * scale
    if dim == 2:
        assert np.all(a[:, 2] == 0.0)


def test_pair_force_is_repulsive_with_the_stated_magnitude():
    # two particles at the initial spacing along x, both in uniaxial tension:
    # f_ij = 1, a_i = m_j (R_i + R_j) F_ij (x_i - x_j), repulsive (a_i,x > 0)
    dim, dx, h, m, s = 2, 1e-3, 1.5e-3, 1.0, 1e6
    kid = kernels.kernel_id("cubic_spline")
    sigma = kernels.normalisation(kid, dim)
    x = np.array([[dx, 0, 0], [0.0, 0, 0]])
    sig = np.zeros((2, 3, 3))
    sig[:, 0, 0] = s
    R = np.zeros((2, 3, 3))
    artificial_stress_tensor(sig, np.full(2, RHO), np.full(2, EPS), R, np.zeros((2, 3, 3)))
    Fij = kernels.grad_factor(kid, sigma, dim, dx, h)
    offsets = np.array([0, 1, 2])
    idx = np.array([1, 0])
    a = np.zeros((2, 3))
    artificial_stress_forces(x, np.full(2, m), np.full(2, h), R, np.full(2, Fij), offsets,
                             idx, kid, dim, 1.0, np.full(2, dx), 4.0, a, np.zeros((2, 3)),
                             np.zeros(2))
    expect = m * 2 * (-EPS * s / RHO**2) * Fij * dx
    assert expect > 0.0
    assert a[0, 0] == pytest.approx(expect, rel=1e-13)
    assert a[1, 0] == pytest.approx(-expect, rel=1e-13)
    # at half the spacing f^4 = (w(q/2)/w(q))^4 amplifies the repulsion
    x[0, 0] = 0.5 * dx
    Fh = kernels.grad_factor(kid, sigma, dim, 0.5 * dx, h)
    f = kernels.w(kid, 0.5 * dx / h) / kernels.w(kid, dx / h)
    a[:] = 0.0
    artificial_stress_forces(x, np.full(2, m), np.full(2, h), R, np.full(2, Fh), offsets,
                             idx, kid, dim, 1.0, np.full(2, dx), 4.0, a, np.zeros((2, 3)),
                             np.zeros(2))
    assert a[0, 0] == pytest.approx(m * 2 * (-EPS * s / RHO**2) * f**4 * Fh * 0.5 * dx,
                                    rel=1e-13)
    # a non-integer exponent (pow instead of repeated squaring): f^2.5
    a[:] = 0.0
    artificial_stress_forces(x, np.full(2, m), np.full(2, h), R, np.full(2, Fh), offsets,
                             idx, kid, dim, 1.0, np.full(2, dx), 2.5, a, np.zeros((2, 3)),
                             np.zeros(2))
    assert a[0, 0] == pytest.approx(m * 2 * (-EPS * s / RHO**2) * f**2.5 * Fh * 0.5 * dx,
                                    rel=1e-13)


DECK = """
[run]
dimension = 2
t_end = 1e-4
[sph]
artificial_stress = {{ epsilon = {eps} }}
[[material]]
name = "m"
model = "elastic"
density = 1000.0
E = 1.0e7
nu = 0.3
[[body]]
name = "b"
material = "m"
dx = 0.001
velocity = [1.0, 0]
geometry = {{ shape = "box", lo = [0, 0], hi = [0.01, 0.01] }}
"""


def test_deck_defaults_and_bounds():
    d = loads_deck(DECK.format(eps=0.3))
    assert d.sph.artificial_stress.epsilon == 0.3
    assert d.sph.artificial_stress.n == 4.0
    off = loads_deck(DECK.format(eps=0.0))
    assert not build_stepper(off).part("sph").as_on  # off costs nothing
    with pytest.raises(DeckError):
        loads_deck(DECK.format(eps=-0.1))


def test_solver_with_artificial_stress_conserves_momentum():
    # free body in uniform motion: total momentum unchanged to round-off
    d = loads_deck(DECK.format(eps=0.3))
    s = build_stepper(d)
    p = s.part("sph").kin
    p.v[:, 1] = 0.3 * np.sin(300.0 * p.x[:, 0])  # shear, tension and compression
    p0 = (p.m[:, None] * p.v).sum(axis=0)
    for _ in range(30):
        s.step()
    p1 = (p.m[:, None] * p.v).sum(axis=0)
    assert np.abs(p.sig).max() > 0
    assert np.abs(p1 - p0).max() < 1e-12 * np.abs(p.m[:, None] * p.v).sum()


def test_epsilon_per_body():
    # A second body with its own epsilon = 0 gets no artificial stress
    # (R = 0 on its rows, even under tension), the first keeps the deck's;
    # only [sph] epsilon = 0 with a body's epsilon > 0 switches the passes on.
    second = DECK.format(eps=0.3).replace('name = "b"', 'name = "b"', 1) + """
[[body]]
name = "c"
material = "m"
dx = 0.001
artificial_stress = 0.0
geometry = { shape = "box", lo = [0.02, 0], hi = [0.03, 0.01] }
"""
    d = loads_deck(second)
    s = build_stepper(d)
    p = s.part("sph").kin
    assert np.array_equal(s.part("sph").kin.as_eps, np.where(p.body == 0, 0.3, 0.0))
    p.sig[:] = 0.0
    p.sig[:, 0, 0] = 1e5  # uniaxial tension everywhere
    s.part("sph")._accelerations()
    R = s.part("sph").kin.R
    assert np.all(R[p.body == 1] == 0.0)
    # first body: R = diag(-eps sigma_xx / rho^2, 0, 0) (Gray et al. 2001,
    # eq. 4.8) with its own density; a diagonal stress needs no Jacobi
    # rotation, so only the rounding of the product: 1e-14 relative
    first = p.body == 0
    expect = -0.3 * 1e5 / p.rho[first] ** 2
    assert np.allclose(R[first, 0, 0], expect, rtol=1e-14, atol=0.0)
    R_rest = R[first].copy()
    R_rest[:, 0, 0] = 0.0
    assert np.all(R_rest == 0.0)
    only = DECK.format(eps=0.0).replace("velocity = [1.0, 0]",
                                        "velocity = [1.0, 0]\nartificial_stress = 0.2")
    d = loads_deck(only)
    assert build_stepper(d).part("sph").as_on


def test_artificial_stress_power_is_booked_as_heat():
    # dedt_i -= a_AS_i . v_i (docstring of artificial_stress_forces): with a
    # and dedt starting at zero, each particle's heating rate is minus the
    # power per unit mass of its artificial-stress acceleration, so
    # sum m (a . v + dedt) = 0 and E_total closes (rings test).
    c = _cloud(2)
    n = c["x"].shape[0]
    R = np.zeros((n, 3, 3))
    artificial_stress_tensor(c["sig"], c["rho"], np.full(n, EPS), R, np.zeros((n, 3, 3)))
    v = np.random.default_rng(4).normal(size=(n, 3))
    v[:, 2] = 0.0
    a = np.zeros((n, 3))
    dedt = np.zeros(n)
    nl = c["nl"]
    artificial_stress_forces(c["x"], c["m"], c["h"], R, c["F"], nl.offsets, nl.idx,
                             c["kid"], 2, 1.0, c["spacing"], 4.0, a, v, dedt)
    assert np.abs(a).max() > 0
    assert np.allclose(dedt, -(a * v).sum(axis=1), rtol=1e-14, atol=0)
