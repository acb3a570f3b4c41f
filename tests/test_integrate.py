"""Leapfrog order of accuracy and kick bookkeeping (sphdyn.integrate)."""

import numpy as np
import pytest

from sphdyn.integrate import cfl_mass_factors, cfl_time_step, drift, kick, kick_scratch
from sphdyn.state import BC_FIXED, BC_VELOCITY


def _oscillator(dt, t_end, omega=2.0):
    """x'' = -omega^2 x with the solver's kick/drift kernels, in 3D.

    Each component is its own oscillator (amplitudes 1, -0.5, 0.25), so a
    wrong line for any one component of the kick or the drift shows.
    """
    x = np.array([[1.0, -0.5, 0.25]])
    v = np.zeros((1, 3))
    a = -omega**2 * x
    m = np.ones(1)
    bc = np.zeros(1, np.int8)
    zeros = np.zeros((1, 3))
    vm = np.zeros((1, 3))
    nsteps = int(round(t_end / dt))
    for k in range(nsteps):
        kick(v, a, zeros, m, bc, zeros, 0.5 * dt if k == 0 else dt, vm, kick_scratch(len(m)))
        drift(x, v, dt)
        a = -omega**2 * x
    kick(v, a, zeros, m, bc, zeros, 0.5 * dt, vm, kick_scratch(len(m)))  # synchronise v to t_end
    return x[0].copy(), v[0].copy()


def test_leapfrog_is_second_order():
    # Halving dt divides the error by 4 for a second-order scheme; the ratio
    # is within 4 +- 0.1 in the asymptotic range (dt omega <= 0.05), in every
    # component.
    omega, t_end = 2.0, 3.0
    exact = np.array([1.0, -0.5, 0.25]) * np.cos(omega * t_end)
    errs = [np.abs(_oscillator(dt, t_end, omega)[0] - exact) for dt in (0.02, 0.01, 0.005)]
    assert np.all(np.abs(errs[0] / errs[1] - 4) < 0.1)
    assert np.all(np.abs(errs[1] / errs[2] - 4) < 0.1)


def test_kick_energy_and_boundary_conditions():
    v = np.array([[1.0, 0, 0], [2.0, 0, 0], [0.0, 3.0, 0]])
    a = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1.0, 0]])
    ac = np.zeros((3, 3))
    ac[0, 0] = 0.0
    m = np.array([1.0, 2.0, 3.0])
    bc = np.array([0, BC_FIXED, BC_VELOCITY], np.int8)
    bcv = np.zeros((3, 3))
    bcv[2] = [0, 5.0, 0]
    vm = np.zeros((3, 3))
    ke, wc, we = kick(v, a, ac, m, bc, bcv, 0.1, vm, kick_scratch(len(m)))
    assert np.allclose(v, [[1, 0, 0], [0, 0, 0], [0, 5, 0]])
    # kinetic energy at the kick time uses the mean velocity
    assert np.isclose(ke, 0.5 * (1 * 1**2 + 2 * 1.0**2 + 3 * 4.0**2))
    # work of the BC reactions: m (v_target - v_free) . v_mean
    we_exact = 2 * (0 - 2.1) * 1.0 + 3 * (5 - 3.1) * 4.0
    assert np.isclose(we, we_exact)
    assert wc == 0.0


def test_cfl_time_step_picks_the_controlling_particle():
    h = np.array([1e-3, 2e-3, 1e-3])
    c = np.array([1000.0, 1000.0, 3000.0])
    v = np.zeros((3, 3))
    v[0, 0] = 1000.0
    one, zero = np.ones(3), np.zeros(3)
    dt, k = cfl_time_step(h, c, v, zero, zero, one, one, 1.0, 0.3)
    assert k == 2 and np.isclose(dt, 0.3 * 1e-3 / 3000.0)
    # a material's factor, and a fluid's viscous signal speed (weight 1.2)
    dt, k = cfl_time_step(h, c, v, zero, zero, np.array([1.0, 0.1, 1.0]), one, 1.0, 0.3)
    assert k == 1 and np.isclose(dt, 0.3 * 0.1 * 2e-3 / 1000.0)
    signal = np.array([0.0, 0.0, 4000.0])
    dt, k = cfl_time_step(h, c, v, signal, np.array([0.0, 0.0, 1.2]), one, one, 1.0, 0.3)
    assert k == 2 and np.isclose(dt, 0.3 * 1e-3 / (3000.0 + 1.2 * 4000.0))
    dt, k = cfl_time_step(h, c, v, signal, zero, one, one, 1.0, 0.3)  # a solid ignores it
    assert k == 2 and np.isclose(dt, 0.3 * 1e-3 / 3000.0)
    # mass scaling's wave-speed factor r slows the waves, c and the viscous
    # signal alike, not the particle's own speed
    r = np.array([1.0, 1.0, 0.25])
    dt, k = cfl_time_step(h, c, v, signal, np.array([0.0, 0.0, 1.2]), one, r, 1.0, 0.3)
    assert np.isclose(dt, min(0.3 * 1e-3 / (0.25 * (3000.0 + 1.2 * 4000.0)),
                              0.3 * 1e-3 / (1000.0 + 1000.0), 0.3 * 2e-3 / 1000.0))


def test_cfl_mass_factors_solve_the_cfl_step_for_the_target():
    """r = (C f s h / target - |v|) / (c + w v_sig) below the target (the step
    with it is the target, 1e-12), 1 at or above it, <= 0 where the speed
    alone keeps the step below the target."""
    h = np.array([1e-3, 1e-3, 1e-3, 1e-3])
    c = np.array([5000.0, 1000.0, 5000.0, 5000.0])
    v = np.zeros((4, 3))
    v[2, 0] = 500.0
    v[3, 0] = 5000.0
    signal, viscous, one = np.zeros(4), np.zeros(4), np.ones(4)
    target = 0.3 * 1e-3 / 2000.0
    r = np.zeros(4)
    cfl_mass_factors(h, c, v, signal, viscous, one, 1.0, 0.3, target, r)
    assert r[1] == 1.0  # its step, 0.3 h / 1000, is above the target
    assert r[0] == pytest.approx(2000.0 / 5000.0, rel=1e-12)
    assert r[2] == pytest.approx((2000.0 - 500.0) / 5000.0, rel=1e-12)
    assert r[3] <= 0.0
    dt, _ = cfl_time_step(h[:3], c[:3], v[:3], signal[:3], viscous[:3], one[:3], r[:3],
                          1.0, 0.3)
    assert dt == pytest.approx(target, rel=1e-12)


def test_kick_books_the_contact_work_and_energies_over_several_blocks():
    # 2.5 KICK_BLOCKs of particles with random masses, velocities,
    # accelerations and a nonzero contact acceleration a_c (part of a), a
    # fifth of them fixed or with a prescribed velocity: the kick returns
    #   kinetic       = 1/2 sum m |v^n|^2,
    #   contact work  = sum m a_c . v^n dt,
    #   external work = sum m (v_target - v_free) . (v^{n-1/2} + v_target)/2
    # with v^n = (v^{n-1/2} + v^{n+1/2}) / 2 (docstring of kick), written out
    # here with numpy. Tolerance 1e-12 relative: the same sums taken in
    # another order (blocks); a halved or doubled term is off by O(1).
    from sphdyn.integrate import KICK_BLOCK
    rng = np.random.default_rng(11)
    n = 2 * KICK_BLOCK + KICK_BLOCK // 2
    m = rng.uniform(0.5, 2.0, n)
    v = rng.normal(size=(n, 3))
    ac = rng.normal(size=(n, 3)) * 40.0
    a = ac + rng.normal(size=(n, 3)) * 10.0
    bc = rng.choice(np.array([0, BC_FIXED, BC_VELOCITY], np.int8), n, p=[0.8, 0.1, 0.1])
    bcv = np.where((bc == BC_VELOCITY)[:, None], rng.normal(size=(n, 3)), 0.0)
    dt = 0.01
    v_old = v.copy()
    free = v_old + dt * a
    new = np.where((bc == 0)[:, None], free, bcv)  # fixed: bcv is zero there
    mean = 0.5 * (v_old + new)
    vm = np.zeros((n, 3))
    ke, wc, we = kick(v, a, ac, m, bc, bcv, dt, vm, kick_scratch(n))
    assert np.array_equal(v, new) and np.allclose(vm, mean, rtol=0, atol=1e-15)
    ke_exact = 0.5 * np.sum(m * np.sum(mean**2, axis=1))
    wc_exact = dt * np.sum(m * np.sum(ac * mean, axis=1))
    we_exact = np.sum(m * np.sum((new - free) * mean, axis=1) * (bc != 0))
    assert abs(wc_exact) > 1.0 and abs(we_exact) > 1.0  # neither is a trivial 0
    assert ke == pytest.approx(ke_exact, rel=1e-12)
    assert wc == pytest.approx(wc_exact, rel=1e-12)
    assert we == pytest.approx(we_exact, rel=1e-12)
