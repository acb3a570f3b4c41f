"""Material models: single-point strain/stress paths and the group kernels.

Material: steel-like, E = 200 GPa, nu = 0.3, sigma_y = 250 MPa, H = 2 GPa.
Tolerances are stated per test; "pure linear algebra" checks use 1e-12
relative (a few hundred float64 additions accumulate < 1e-13).
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq

from sphdyn.materials import (
    ELASTIC,
    J2,
    MaterialModel,
    available_models,
    elastic_point,
    get_model,
    j2_point,
    register,
    von_mises,
)
from sphdyn.materials.base import to_sym6, young_modulus

RHO = 7800.0
E, NU = 200e9, 0.3
SY, H = 250e6, 2e9
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))
M_P = K + 4 * G / 3          # P-wave (constrained) modulus
LAM = K - 2 * G / 3
MAT = dict(density=RHO, E=E, nu=NU, yield_stress=SY, hardening_modulus=H)


def vm(s):
    return von_mises(to_sym6(np.asarray(s, dtype=np.float64)))


def test_young_modulus_inverts_the_moduli_of_e_and_nu():
    """E = 9KG/(3K + G) returns the E that gave K = E/(3(1 - 2nu)) and
    G = E/(2(1 + nu)), for steel and for nearly incompressible and auxetic
    values (round-off), scalars and arrays alike."""
    for e, nu in [(E, NU), (30e9, 0.2), (1e6, 0.499), (1e9, -0.5)]:
        k, g = e / (3 * (1 - 2 * nu)), e / (2 * (1 + nu))
        assert young_modulus(k, g) == pytest.approx(e, rel=1e-13)
    ks, gs = np.array([K, 2 * K]), np.array([G, 2 * G])
    assert np.allclose(young_modulus(ks, gs), [E, 2 * E], rtol=1e-13)


def elastic_step(sig, deps, ep):
    return elastic_point(sig, deps, K, G), ep


def j2_step(sig, deps, ep, h=H):
    return j2_point(sig, deps, K, G, SY, h, ep)


def uniaxial_stress_step(step, sig, ep, dexx):
    """One increment dexx with sigma_yy = sigma_zz = 0 (lateral strain solved).

    brentq to ~4 ulp in the lateral increment b: the residual lateral stress
    is then ~E |b| 1e-15 < 1e-3 Pa, negligible against the checked 1e-9.
    """
    def lateral(b):
        return step(sig, np.diag([dexx, b, b]), ep)[0][1, 1]

    span = 2.0 * abs(dexx)
    b = brentq(lateral, -span, span, xtol=1e-300, rtol=4 * np.finfo(float).eps)
    sig, ep = step(sig, np.diag([dexx, b, b]), ep)
    return sig, ep, b


def kernel_arrays(n, nh=1):
    return dict(rho=np.full(n, RHO), sig=np.zeros((n, 3, 3)), e=np.zeros(n),
                c=np.zeros(n), damage=np.zeros(n), hist=np.zeros((n, nh)))


def call(model, params, idx, L, dt, a):
    model.update(idx, L, dt, a["rho"], a["sig"], a["e"], a["c"], a["damage"],
                 a["hist"], params, np.full(a["rho"].shape[0], 1e-3))


# --------------------------------------------------------------------------
# Elastic paths
# --------------------------------------------------------------------------


@pytest.mark.parametrize("step", [elastic_step, j2_step], ids=["elastic", "j2"])
def test_uniaxial_strain_elastic_range(step):
    """sigma_xx = (K + 4G/3) eps, sigma_yy = sigma_zz = (K - 2G/3) eps; 1e-12."""
    eps_final = 0.8 * SY / (2 * G)      # J2 stays elastic: q = 2G eps < sigma_y
    n = 100
    sig, ep = np.zeros((3, 3)), 0.0
    deps = np.diag([eps_final / n, 0.0, 0.0])
    for _ in range(n):
        sig, ep = step(sig, deps, ep)
    eps = n * (eps_final / n)
    assert ep == 0.0
    np.testing.assert_allclose(sig[0, 0], M_P * eps, rtol=1e-12)
    np.testing.assert_allclose([sig[1, 1], sig[2, 2]], LAM * eps, rtol=1e-12)
    assert np.abs(sig[[0, 0, 1], [1, 2, 2]]).max() == 0.0


def test_uniaxial_stress_elastic():
    """sigma_xx = E eps_xx, lateral strain = -nu eps_xx (1e-9: lateral solve)."""
    n, dexx = 50, -2e-5
    sig, ep, lat = np.zeros((3, 3)), 0.0, 0.0
    for k in range(1, n + 1):
        sig, ep, b = uniaxial_stress_step(elastic_step, sig, ep, dexx)
        lat += b
        np.testing.assert_allclose(sig[0, 0], E * k * dexx, rtol=1e-9)
        np.testing.assert_allclose(lat, -NU * k * dexx, rtol=1e-9)
        assert abs(sig[1, 1]) < 1e-6 and abs(sig[2, 2]) < 1e-6


def test_plane_strain_from_2d_velocity_gradient():
    """L with zero z row/column gives sigma_zz = lambda (eps_xx + eps_yy)."""
    a = kernel_arrays(1)
    L = np.zeros((1, 3, 3))
    L[0, :2, :2] = [[1.0, 0.3], [-0.1, -0.4]]
    dt = 1e-5
    call(ELASTIC, ELASTIC.pack(MAT), np.array([0]), L, dt, a)
    s = a["sig"][0]
    np.testing.assert_allclose(s[2, 2], LAM * (1.0 - 0.4) * dt, rtol=1e-12)
    assert s[0, 2] == s[1, 2] == s[2, 0] == s[2, 1] == 0.0


# --------------------------------------------------------------------------
# J2 plasticity
# --------------------------------------------------------------------------


def test_j2_uniaxial_stress_bilinear_and_unloading():
    """Bilinear sigma = sigma_y + E_t (eps - eps_y), E_t = E H / (E + H).

    Along uniaxial stress the deviatoric direction is fixed, so radial return
    (backward Euler with a fixed normal) is exact for linear hardening, also
    in the increment that crosses the yield point: the tolerance is therefore
    not O(increment) but only the lateral-stress solve + roundoff, 1e-9.
    """
    eps_y = SY / E
    et = E * H / (E + H)
    dexx = eps_y / 7.3                  # yield point falls inside an increment
    sig, ep, eps = np.zeros((3, 3)), 0.0, 0.0
    for _ in range(40):
        sig, ep, _b = uniaxial_stress_step(j2_step, sig, ep, dexx)
        eps += dexx
        expected = E * eps if eps <= eps_y else SY + et * (eps - eps_y)
        np.testing.assert_allclose(sig[0, 0], expected, rtol=1e-9)
        np.testing.assert_allclose(ep, eps - sig[0, 0] / E, rtol=1e-9, atol=1e-15)
    assert ep > 3 * eps_y               # really went plastic
    # Elastic unloading with slope E, plastic strain frozen.
    s_peak, ep_peak = sig[0, 0], ep
    for k in range(1, 11):              # unload by 10 dexx: |d sigma| < 2 sigma
        sig, ep, _b = uniaxial_stress_step(j2_step, sig, ep, -dexx)
        np.testing.assert_allclose(sig[0, 0], s_peak - E * k * dexx, rtol=1e-9)
        assert ep == ep_peak


def test_j2_consistency_and_plastic_incompressibility_mixed_path():
    """Random mixed strain path with loading, unloading and reloading.

    After every plastic return q = sigma_y + H eps_p (1e-10 relative; the
    return enforces it in exact arithmetic). The mean stress stays
    p = -K tr(eps) (Mises flow is deviatoric; 1e-10 of sigma_y + K |eps|), and
    the plastic strain increment deps - C^-1 : dsig is traceless (1e-9 of its
    norm).
    """
    rng = np.random.default_rng(3)
    sig, ep = np.zeros((3, 3)), 0.0
    eps = np.zeros((3, 3))
    direction = np.zeros((3, 3))
    n_plastic = 0
    for k in range(400):
        if k % 40 == 0:                 # new random direction every 40 steps,
            a = rng.normal(size=(3, 3))  # reversed after 20 (unload/reload)
            direction = 0.5 * (a + a.T)
            direction *= 2e-4 / np.linalg.norm(direction)
        deps = direction if k % 40 < 20 else -direction
        new, ep_new = j2_step(sig, deps, ep)
        eps += deps
        dsig = new - sig
        deps_el = (dsig - np.trace(dsig) / 3 * np.eye(3)) / (2 * G) \
            + np.trace(dsig) / (9 * K) * np.eye(3)
        deps_p = deps - deps_el
        if ep_new > ep:
            n_plastic += 1
            np.testing.assert_allclose(vm(new), SY + H * ep_new, rtol=1e-10)
            assert abs(np.trace(deps_p)) <= 1e-9 * np.linalg.norm(deps_p)
        else:
            assert np.abs(deps_p).max() < 1e-12 * np.abs(deps).max()
            assert vm(new) <= (SY + H * ep) * (1 + 1e-12)
        np.testing.assert_allclose(np.trace(new) / 3, K * np.trace(eps),
                                   rtol=0, atol=1e-10 * (SY + K * np.abs(eps).max()))
        sig, ep = new, ep_new
    assert n_plastic > 100 and 400 - n_plastic > 100  # both regimes visited


def test_j2_pure_shear_yields_at_sigma_y_over_sqrt3():
    """Perfect plasticity: tau = 2 G eps_xy until tau_y = sigma_y / sqrt(3), then flat.

    Pure linear algebra on a radial path: 1e-12 relative.
    """
    tau_y = SY / np.sqrt(3)
    d = tau_y / (2 * G) / 9.4           # yield inside an increment
    deps = np.zeros((3, 3))
    deps[0, 1] = deps[1, 0] = d
    sig, ep, exy = np.zeros((3, 3)), 0.0, 0.0
    for _ in range(30):
        sig, ep = j2_step(sig, deps, ep, h=0.0)
        exy += d
        if 2 * G * exy < tau_y * (1 - 1e-12):
            assert ep == 0.0
            np.testing.assert_allclose(sig[0, 1], 2 * G * exy, rtol=1e-12)
        else:
            assert ep > 0.0 or 2 * G * exy <= tau_y * (1 + 1e-12)
            np.testing.assert_allclose(sig[0, 1], tau_y, rtol=1e-12)
        assert np.abs(np.diag(sig)).max() <= 1e-12 * tau_y
    assert ep > 0.0


def test_j2_hydrostatic_path_stays_elastic():
    """Pure pressure far beyond sigma_y: no plastic flow, sigma = K tr(eps) I."""
    for sign in (-1.0, 1.0):
        sig, ep = np.zeros((3, 3)), 0.0
        deps = sign * 1e-3 * np.eye(3)
        for k in range(1, 11):          # |p| up to 5 GPa = 20 sigma_y
            sig, ep = j2_step(sig, deps, ep)
            assert ep == 0.0
            np.testing.assert_allclose(np.diag(sig), K * 3 * k * sign * 1e-3, rtol=1e-12)
            assert vm(sig) < 1e-12 * abs(sig[0, 0])


# --------------------------------------------------------------------------
# Objectivity
# --------------------------------------------------------------------------


def _prestress():
    rng = np.random.default_rng(7)
    a = rng.normal(size=(3, 3)) * 1e8
    return 0.5 * (a + a.T)


def _spin(omega=50.0):
    axis = np.array([1.0, 2.0, -0.5])
    axis /= np.linalg.norm(axis)
    W = omega * np.array([[0, -axis[2], axis[1]],
                          [axis[2], 0, -axis[0]],
                          [-axis[1], axis[0], 0]])
    return W


def _rotate_with_kernel(sig0, W, dt, n):
    a = kernel_arrays(1)
    a["sig"][0] = sig0
    L = W[None].copy()
    for _ in range(n):
        call(ELASTIC, ELASTIC.pack(MAT), np.array([0]), L, dt, a)
    return a["sig"][0].copy(), a["e"][0]


def test_jaumann_single_step_invariants():
    """I1 exact (tr(W s - s W) = 0); J2 grows by exactly dt^2 |W s - s W|^2 / 2.

    (The O(dt) term s:(W s - s W) vanishes.) Checked to 1e-8 relative to that
    O(dt^2) increment, i.e. far below it; the dt^2 scaling is checked too.
    """
    sig0, W = _prestress(), _spin()
    j2 = lambda s: 0.5 * np.sum((s - np.trace(s) / 3 * np.eye(3)) ** 2)  # noqa: E731
    R = W @ sig0 - sig0 @ W
    growth = []
    for dt in (1e-4, 5e-5):
        s1, e1 = _rotate_with_kernel(sig0, W, dt, 1)
        assert e1 == 0.0                            # D = 0: no work
        np.testing.assert_allclose(np.trace(s1), np.trace(sig0), rtol=1e-14,
                                   atol=1e-14 * np.abs(sig0).max())
        dj2 = j2(s1) - j2(sig0)
        np.testing.assert_allclose(dj2, 0.5 * dt**2 * np.sum(R**2), rtol=1e-6)
        growth.append(dj2)
    np.testing.assert_allclose(growth[0] / growth[1], 4.0, rtol=1e-5)


def test_jaumann_rigid_rotation_matches_r_sigma_rt():
    """Rigid spin of a pre-stressed point: sigma(t) -> R sigma0 R^T, R = exp(W t).

    Forward-Euler Jaumann: global error O(dt), so halving dt halves the
    error (ratio 2 +- 10 %), and with 0.2 rad in 400 steps the error is
    < 1e-3 of |sigma0| (expected ~theta^2/(2n) ~ 5e-5 times a norm factor).
    A wrong spin sign would give an O(theta) = 20 % error.
    """
    sig0, W = _prestress(), _spin()
    t_end = 0.2 / 50.0
    errs = []
    for n in (200, 400):
        s, _ = _rotate_with_kernel(sig0, W, t_end / n, n)
        R = expm(W * t_end)
        errs.append(np.linalg.norm(s - R @ sig0 @ R.T) / np.linalg.norm(sig0))
    assert errs[1] < 1e-3
    assert 1.8 < errs[0] / errs[1] < 2.2


# --------------------------------------------------------------------------
# Energy
# --------------------------------------------------------------------------


def test_energy_elastic_load_unload():
    """e * rho = sum of trapezoids 1/2 (s_k + s_k+1) : deps = 1/2 sigma : eps.

    The trapezoidal rule is exact for a linear stress-strain path, so all
    three agree to roundoff (1e-12); after unloading to eps = 0 the energy
    is back to 0 within 1e-12 of the peak.
    """
    rng = np.random.default_rng(11)
    a0 = rng.normal(size=(3, 3))
    D = 0.5 * (a0 + a0.T)
    D *= 20.0 / np.linalg.norm(D)       # 1/s
    dt, n = 1e-6, 60                    # |eps| = 1.2e-3
    a = kernel_arrays(1)
    params = ELASTIC.pack(MAT)
    work = 0.0
    for L in (D, -D):
        for _ in range(n):
            s_old = a["sig"][0].copy()
            call(ELASTIC, params, np.array([0]), L[None], dt, a)
            work += np.sum(0.5 * (s_old + a["sig"][0]) * L * dt)
        if L is D:
            peak = a["e"][0] * RHO
            eps = D * dt * n
            np.testing.assert_allclose(peak, work, rtol=1e-12)
            np.testing.assert_allclose(peak, 0.5 * np.sum(a["sig"][0] * eps), rtol=1e-12)
            assert peak > 0
    assert abs(a["e"][0] * RHO) < 1e-12 * peak
    assert abs(work) < 1e-12 * peak


def test_energy_j2_equals_elastic_plus_plastic_work():
    """Uniaxial strain load/unload (with reverse yielding) through the kernel.

    e * rho = W_el + W_p with W_el = p^2/(2K) + s:s/(4G) and the dissipation
    W_p = int (sigma_y + H eps_p) d eps_p = sigma_y eps_p + H eps_p^2 / 2.
    The kernel's trapezoidal rule is exact on linear segments; only the
    increments containing a yield kink err, each by at most
    (M_el - M_pl) deps^2 / 8 (chord vs. kinked line), M = d sigma_xx/d eps.
    """
    rate, dt = 10.0, 1e-6
    deps = rate * dt
    eps_y = SY / (2 * G) * 0.999        # ~ onset in uniaxial strain
    n_load = int(6 * eps_y / deps)
    L = np.zeros((1, 3, 3))
    a = kernel_arrays(1)
    params = J2.pack(MAT)
    for sign, steps in ((1.0, n_load), (-1.0, 2 * n_load)):
        L[0, 0, 0] = sign * rate
        for _ in range(steps):
            call(J2, params, np.array([0]), L, dt, a)
    s, ep = a["sig"][0], a["hist"][0, 0]
    assert ep > 6 * eps_y               # yielded in both directions
    p = -np.trace(s) / 3
    dev = s + p * np.eye(3)
    w_el = p**2 / (2 * K) + np.sum(dev**2) / (4 * G)
    w_p = SY * ep + 0.5 * H * ep**2
    m_pl = K + 4 * G / 3 * H / (3 * G + H)
    tol = 2 * (M_P - m_pl) * deps**2 / 8 + 1e-12 * (w_el + w_p)
    assert abs(a["e"][0] * RHO - (w_el + w_p)) <= tol
    assert w_p > 1e4 * tol              # the check resolves the dissipation


# --------------------------------------------------------------------------
# Group kernels
# --------------------------------------------------------------------------


def _random_state(n, seed):
    rng = np.random.default_rng(seed)
    a = kernel_arrays(n)
    s = rng.normal(size=(n, 3, 3))
    s = 0.5 * (s + s.transpose(0, 2, 1))
    # scale deviators to ~ the yield surface so that some particles yield
    for i in range(n):
        s[i] *= SY * rng.uniform(0.9, 1.1) / max(vm(s[i]), 1.0)
    a["sig"][:] = s
    a["rho"][:] = RHO * rng.uniform(0.9, 1.1, n)
    a["e"][:] = rng.uniform(0, 100, n)
    a["c"][:] = -1.0
    a["damage"][:] = rng.uniform(0, 0.5, n)
    a["hist"][:, 0] = rng.uniform(0, 0.01, n)
    L = rng.normal(size=(n, 3, 3)) * 30.0
    return a, L


@pytest.mark.parametrize("model", [ELASTIC, J2], ids=["elastic", "j2"])
def test_group_kernel_matches_point_function(model):
    """Kernel = numpy Jaumann rotation + point function + trapezoidal energy.

    Only the order of floating-point operations differs: 1e-12 relative on
    stress, 1e-9 on the energy increment (a difference of near-equal terms);
    particles outside idx are bit-for-bit unchanged.
    """
    n, dt = 9, 2e-6
    idx = np.array([1, 4, 5, 8], dtype=np.int64)
    a, L = _random_state(n, seed=5)
    before = {k: v.copy() for k, v in a.items()}
    params = model.pack(MAT)
    call(model, params, idx, L, dt, a)
    n_yield = 0
    for i in range(n):
        if i not in idx:
            for k, v in a.items():
                assert np.array_equal(v[i], before[k][i]), (k, i)
            continue
        s0 = before["sig"][i]
        Dm = 0.5 * (L[i] + L[i].T)
        W = 0.5 * (L[i] - L[i].T)
        sr = s0 + dt * (W @ s0 - s0 @ W)
        if model is J2:
            s_new, ep = j2_point(sr, Dm * dt, K, G, SY, H, before["hist"][i, 0])
            n_yield += ep > before["hist"][i, 0]
            np.testing.assert_allclose(a["hist"][i, 0], ep, rtol=1e-12)
        else:
            s_new = elastic_point(sr, Dm * dt, K, G)
            assert a["hist"][i, 0] == before["hist"][i, 0]
        np.testing.assert_allclose(a["sig"][i], s_new, rtol=0, atol=1e-12 * SY)
        assert np.array_equal(a["sig"][i], a["sig"][i].T)
        de = dt * 0.5 * np.sum((sr + s_new) * Dm) / a["rho"][i]
        np.testing.assert_allclose(a["e"][i] - before["e"][i], de, rtol=1e-9)
        np.testing.assert_allclose(a["c"][i], model.wave_speed(params, a["rho"][i]),
                                   rtol=1e-14)
        np.testing.assert_allclose(a["c"][i], np.sqrt(M_P / a["rho"][i]), rtol=1e-12)
        assert a["damage"][i] == before["damage"][i]
    if model is J2:
        assert 0 < n_yield < len(idx)   # both branches exercised


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 threads")
@pytest.mark.parametrize("model", [ELASTIC, J2], ids=["elastic", "j2"])
def test_group_kernel_thread_independent(model):
    """Gather form: results bit-identical with 1 and 2 Numba threads."""
    n = 2000
    idx = np.arange(0, n, 3, dtype=np.int64)
    a1, L = _random_state(n, seed=9)
    a2 = {k: v.copy() for k, v in a1.items()}
    params = model.pack(MAT)
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        call(model, params, idx, L, 1e-6, a1)
        numba.set_num_threads(2)
        call(model, params, idx, L, 1e-6, a2)
    finally:
        numba.set_num_threads(old)
    for k in a1:
        assert np.array_equal(a1[k], a2[k]), k


# --------------------------------------------------------------------------
# Registry and parameters
# --------------------------------------------------------------------------


def test_registry_lookup():
    assert get_model("elastic") is ELASTIC
    assert get_model("j2") is J2
    assert {"elastic", "j2"} <= set(available_models())
    assert J2.history_names == ("plastic_strain",) and ELASTIC.history_names == ()
    assert np.array_equal(J2.initial_history(J2.pack(MAT)), [0.0])
    with pytest.raises(KeyError, match="elastic.*j2"):
        get_model("cscm_typo")
    with pytest.raises(ValueError, match="already registered"):
        register(MaterialModel("elastic", (), ELASTIC.pack, ELASTIC.update))


def test_pack_values_and_errors():
    p = J2.pack(MAT)
    np.testing.assert_allclose(p, [RHO, K, G, SY, H], rtol=1e-15)
    np.testing.assert_allclose(ELASTIC.pack(dict(density=RHO, K=K, G=G)),
                               ELASTIC.pack(MAT), rtol=1e-15)
    assert J2.bulk_modulus(p) == p[1] and J2.shear_modulus(p) == p[2]
    np.testing.assert_allclose(J2.wave_speed(p, RHO), np.sqrt(M_P / RHO), rtol=1e-15)
    # perfect plasticity by default
    assert J2.pack({k: v for k, v in MAT.items() if k != "hardening_modulus"})[4] == 0.0
    bad = [
        ({k: v for k, v in MAT.items() if k != "yield_stress"}, "yield_stress"),
        ({k: v for k, v in MAT.items() if k != "density"}, "density"),
        ({**MAT, "nu": 0.5}, "nu"),
        ({**MAT, "E": -1.0}, "E"),
        ({**MAT, "yield_stress": "abc"}, "yield_stress"),
        ({**MAT, "hardening_modulus": float("nan")}, "hardening_modulus"),
        ({**MAT, "K": 1e9}, "K"),
    ]
    for values, key in bad:
        with pytest.raises(ValueError, match=key):
            J2.pack(values)
    with pytest.raises(ValueError, match="'G'"):
        ELASTIC.pack(dict(density=RHO, K=K))
