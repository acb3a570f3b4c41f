"""CSCM concrete model (LS-DYNA MAT_159 re-implementation): defaults,
surfaces, single-point paths, regularisation, rate effects, robustness.

Reference values come from ``cscm-notes.md`` (sections cited per test) and
the paper's Table 1 (f'c 43.10 MPa, G 12.92 GPa, K 14.15 GPa, GF 83.25 J/m2,
dagg 8 mm). Stresses are tension positive; CSCM's J1 is compression positive.
Tolerances are stated per test with the reason.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from sphdyn.materials import cscm, get_model
from sphdyn.materials.cscm import default_parameters, elastic_moduli
from sphdyn.materials.driver import drive

numba.set_num_threads(1)

MPA = 1e6
BASE = dict(density=2400.0, fc=43.1e6, aggregate_size=0.008)


def packed(**kw):
    return cscm.pack_cscm({**BASE, **kw})


def post_peak_area(res):
    """Area under |stress| vs |strain| from the peak on [Pa]."""
    x, y = np.abs(res["x"]), np.abs(res["y"])
    i = int(np.argmax(y))
    return float(np.trapezoid(y[i:], x[i:]))


# --------------------------------------------------------------------------
# Defaults (notes sec. 2)
# --------------------------------------------------------------------------


def test_table1_moduli_within_0p2_percent():
    # Table 1: G = 12.92 GPa, K = 14.15 GPa; the MAT_159 rule gives 12.931 /
    # 14.162 (notes sec. 2.3: +0.08 %). 0.2 % is the brief's tolerance.
    K, G = elastic_moduli(43.1e6)
    assert abs(G / 12.92e9 - 1) < 2e-3
    assert abs(K / 14.15e9 - 1) < 2e-3
    E = 9 * K * G / (3 * K + G)
    assert E == pytest.approx(18.275e9 * 4.31 ** (1 / 3), rel=1e-12)
    assert (3 * K - 2 * G) / (2 * (3 * K + G)) == pytest.approx(0.15, rel=1e-12)


def test_fracture_energy_default_as_in_notes():
    # The notes (sec. 2.3) say the reconstructed CEB rule gives 69.51 J/m2 at
    # dagg = 8 mm, NOT the paper's 83.25; the paper's value is reproduced
    # (+0.2 %) with dagg = 16 mm. Both facts are checked; 0.05 % / 0.3 %
    # cover the 4-5 digits quoted in the notes.
    p8 = default_parameters(43.1e6, 0.008)
    p16 = default_parameters(43.1e6, 0.016)
    assert p8["GFT"] == pytest.approx(69.5143, rel=5e-4)
    assert p16["GFT"] == pytest.approx(83.25, rel=3e-3)
    assert abs(p8["GFT"] / 83.25 - 1) > 0.15
    assert p8["GFS"] == p8["GFT"] and p8["GFC"] == pytest.approx(100 * p8["GFT"])


def test_default_fits_match_notes_table():
    # notes sec. 2.4 column fc = 43.1 (values printed with 5-6 digits).
    p = default_parameters(43.1e6, 0.008)
    assert p["alpha"] == pytest.approx(15.7935e6, rel=1e-5)
    assert p["theta"] == pytest.approx(0.340048, rel=1e-5)
    assert p["X0"] == pytest.approx(97.9804e6, rel=1e-5)
    assert p["beta1"] == pytest.approx(0.0544121e-6, rel=1e-5)
    assert p["eta0c"] == pytest.approx(0.000155972, rel=1e-4)
    assert p["eta0t"] == pytest.approx(7.61419e-05, rel=1e-4)
    assert p["overc"] == pytest.approx(28.8502e6, rel=1e-5)
    assert cscm.kappa0(packed()) == pytest.approx(20.208e6, rel=1e-4)


def test_overrides_and_unknown_names():
    p = cscm.cscm_parameters({**BASE, "G": 10e9, "GFT": 100.0})
    assert p["G"] == 10e9 and p["GFT"] == 100.0 and p["GFS"] == pytest.approx(69.5143, rel=5e-4)
    with pytest.raises(ValueError, match="unknown parameter"):
        default_parameters(43.1e6, 0.008, bogus=1.0)
    with pytest.raises(ValueError, match="density"):
        cscm.pack_cscm({"fc": 30e6})


# --------------------------------------------------------------------------
# Surfaces (notes sec. 1.4-1.7)
# --------------------------------------------------------------------------


def test_rubin_identities():
    # notes sec. 1.6: R(TXC) = 1, R(TOR) = Q1, R(TXE) = Q2; at J1 = 30 MPa
    # Q1 = 0.736563, Q2 = 0.656536. Closed-form algebra: 1e-12.
    p = packed()
    q1, q2 = cscm.rubin_q(30e6, p)
    assert q1 == pytest.approx(0.736563, abs=1e-6)
    assert q2 == pytest.approx(0.656536, abs=1e-6)
    assert cscm.rubin_factor(q1, q2, math.pi / 6) == pytest.approx(1.0, abs=1e-12)
    assert cscm.rubin_factor(q1, q2, 0.0) == pytest.approx(q1, abs=1e-12)
    assert cscm.rubin_factor(q1, q2, -math.pi / 6) == pytest.approx(q2, abs=1e-12)
    # tensile-pressure clamp: Q1 = 1/sqrt(3), Q2 = 1/2 for J1 <= 0
    q1t, q2t = cscm.rubin_q(-5e6, p)
    assert q1t == pytest.approx(1 / math.sqrt(3), abs=1e-4)
    assert q2t == pytest.approx(0.5, abs=1e-12)


def test_lode_angle_sign_convention():
    # tension-positive uniaxial compression is TXC (+pi/6), tension TXE.
    J1, r, b, _ = cscm.invariants((-10e6, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert J1 == pytest.approx(10e6) and b == pytest.approx(math.pi / 6, abs=1e-7)
    J1, r, b, _ = cscm.invariants((10e6, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert J1 == pytest.approx(-10e6) and b == pytest.approx(-math.pi / 6, abs=1e-7)
    J1, r, b, _ = cscm.invariants((0.0, 0.0, 0.0, 5e6, 0.0, 0.0))
    assert b == pytest.approx(0.0, abs=1e-12) and r == pytest.approx(5e6)


def test_tiny_deviator_keeps_its_angle_and_cannot_divide_by_zero():
    # A deviator of 1e-110 Pa (velocity gradients of 1e-113 /s reach the
    # first particles at contact) has J2'^(3/2) ~ 1e-330, below the smallest
    # double: the Lode ratio once divided by zero there, inside a parallel
    # kernel that swallowed the error and failed the next run of the
    # process. The invariants are homogeneous in the stress: the angle is
    # that of the same deviator at 1 MPa and sqrt(J2') scales with it
    # (relative 1e-14, a few roundings).
    base = (-2.0, 1.0, 1.0, 0.3, 0.1, 0.0)
    _, r1, b1, _ = cscm.invariants(tuple(1e6 * v for v in base))
    for scale in (1e-110, 1e-200, 1e-300):
        _, r, b, _ = cscm.invariants(tuple(scale * v for v in base))
        assert b == pytest.approx(b1, rel=1e-14)
        assert r == pytest.approx(r1 * scale / 1e6, rel=1e-14)
    # and a whole CSCM point update from rest by such an increment
    p = get_model("cscm").pack({"density": 2400.0, "fc": 43.1e6})
    h = cscm.initial_history(p).copy()
    s, d = cscm.cscm_point(h, (-1e-120, 1e-120, 0.0, 1e-121, 0.0, 3e-121), 2e-7, p, 0.0025)
    assert d == 0.0 and all(math.isfinite(v) and abs(v) < 1e-100 for v in s)


def test_dilogarithm():
    # Li2(-1) = -pi^2/12; Li2(-100) from the inversion formula vs direct
    # numerical integral -int_0^inf x/(e^x/B + 1) dx. 1e-10 / 1e-8.
    assert cscm.dilog_neg(1.0) == pytest.approx(-math.pi ** 2 / 12, abs=1e-10)
    x = np.linspace(0, 60, 200001)
    ref = -np.trapezoid(x / (np.exp(x) / 100 + 1), x)
    assert cscm.dilog_neg(100.0) == pytest.approx(ref, rel=1e-8)


# --------------------------------------------------------------------------
# Single-point paths
# --------------------------------------------------------------------------


def test_hydrostatic_compaction_law():
    # notes sec. 1.7 / 3: elastic until P = X0/3, then
    # ev = W [1 - exp(-D1 (X - X0) - D2 (X - X0)^2)] with X = 3P, -> W.
    p = packed()
    res = drive("cscm", BASE, "hydrostatic", strain=0.1, n_steps=1000)
    P = res["y"]
    ev = res["history"][:, res["history_names"].index("plastic_vol_strain")]
    i = int(np.argmax(ev > 0))
    # onset bracketed by the last elastic and first plastic sample
    assert P[i - 1] <= p[cscm.P_X0] / 3 <= P[i]
    # elastic part: P = K eps_v exactly (linear algebra, 1e-9)
    assert P[i - 1] == pytest.approx(p[cscm.P_K] * res["x"][i - 1], rel=1e-9)
    X = 3 * P[i:]
    y = X - p[cscm.P_X0]
    law = p[cscm.P_W] * (1 - np.exp(-p[cscm.P_D1] * y - p[cscm.P_D2] * y * y))
    # explicit cap update: the cap lags one sub-increment (<= incre in
    # strain, i.e. <= 3K incre in J1); 1e-4 absolute = 0.2 % of W covers it
    assert np.max(np.abs(ev[i:] - law)) < 1e-4
    assert 0.85 * p[cscm.P_W] < ev[-1] < p[cscm.P_W]
    assert res["damage"].max() < 1e-6   # no damage on the hydrostat


@pytest.mark.parametrize("fc, expected", [(28e6, 28.009e6), (43.1e6, 42.529e6)])
def test_uniaxial_compression_peak(fc, expected):
    # peak = first yield (no pre-peak hardening); notes sec. 2.4 f_uc:
    # 28.009 / 42.529 MPa. Brief: within 2 % of f'c; the notes' first-yield
    # value itself is checked to 0.1 % (driver step 2.5e-5 strain).
    res = drive("cscm", {**BASE, "fc": fc}, "uniaxial-compression", strain=0.006,
                n_steps=240)
    peak = -res["y"].min()
    assert abs(peak / fc - 1) < 0.02
    assert peak == pytest.approx(expected, rel=1e-3)
    # lateral stresses held at zero by the mixed control (tolerance 1e-9 K)
    assert np.max(np.abs(res["stress"][:, 1:3])) < 1e-8 * 14.2e9


def test_uniaxial_tension_peak_is_model_tensile_strength():
    # f_ut from the yield surface along the UT line (bisection), notes sec.
    # 2.4: 3.1074 MPa at 43.1. Driver step 1.5e-6 strain ~ 0.05 MPa, but the
    # peak sample is the yield point itself (onset inside the step): 0.5 %.
    p = packed()
    lo, hi = 0.0, 10e6
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if cscm.yield_function((mid, 0, 0, 0, 0, 0), p[cscm.P_KAPPA0], p) > 0:
            hi = mid
        else:
            lo = mid
    assert lo == pytest.approx(3.1074e6, rel=1e-4)
    res = drive("cscm", BASE, "uniaxial-tension", strain=4e-4, n_steps=270)
    assert res["y"].max() == pytest.approx(lo, rel=5e-3)


def test_pure_shear_peak():
    # notes sec. 2.4 tau_sh = Q1(0) Ff(0) = 3.0562 MPa; 0.5 % (step size).
    res = drive("cscm", BASE, "shear", strain=1e-3, n_steps=200)
    assert np.max(np.abs(res["y"])) == pytest.approx(3.0562e6, rel=5e-3)


@pytest.mark.parametrize("size", [0.005, 0.02])
def test_tension_fracture_energy_regularised(size):
    # L * area under the post-peak stress-strain curve = GFT within 5 % for
    # two sizes 4x apart (notes sec. 1.10: C is derived for exactly this;
    # the 0.1 % residual stress of d = 0.999 and sampling add ~1-2 %).
    p = packed()
    res = drive("cscm", BASE, "uniaxial-tension", strain=3e-4 / size, n_steps=2000,
                size=size)
    assert res["damage"][-1] > 0.998
    assert size * post_peak_area(res) == pytest.approx(p[cscm.P_GFT], rel=0.05)


@pytest.mark.parametrize("size", [0.005, 0.02])
def test_compression_fracture_energy_regularised(size):
    # same with GFC = 100 GFT in uniaxial compression (ductile law, A from
    # the quadratic of notes sec. 1.10); 5 %.
    p = packed()
    res = drive("cscm", BASE, "uniaxial-compression", strain=1e-3 / size,
                n_steps=1500, size=size)
    assert res["damage"][-1] > 0.998
    assert size * post_peak_area(res) == pytest.approx(p[cscm.P_GFC], rel=0.05)


def test_softening_scales_with_size():
    # C and A are proportional to L: a 2x larger particle softens over half
    # the post-peak strain. Compare the strain beyond the peak at which
    # d = 0.5 in tension (5 %: sampling of the peak strain).
    s = []
    for size in (0.01, 0.02):
        r = drive("cscm", BASE, "uniaxial-tension", strain=0.01, n_steps=2000, size=size)
        s.append(np.interp(0.5, r["damage"], r["x"]) - r["x"][np.argmax(r["y"])])
    assert s[0] / s[1] == pytest.approx(2.0, rel=0.05)


# --------------------------------------------------------------------------
# Rate effects (notes sec. 1.11)
# --------------------------------------------------------------------------


def _shear_only_uc(p):
    # uniaxial-compression strength of the fully expanded cap (Fc = 1):
    # sigma/sqrt(3) = Ff(J1 = sigma), bisection.
    lo, hi = 1e6, 500e6
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if mid / math.sqrt(3) > cscm.shear_surface(mid, p):
            hi = mid
        else:
            lo = mid
    return lo


@pytest.mark.parametrize("path", ["uniaxial-compression", "uniaxial-tension"])
def test_rate_effects(path):
    p = packed()
    strain = 0.006 if path == "uniaxial-compression" else 0.002
    rates = (1.0, 10.0, 100.0, 1000.0)
    static = np.max(np.abs(drive("cscm", BASE, path, strain=strain, n_steps=300)["y"]))
    # off by default: the rate does not matter (1e-6: only the round-off of
    # L = deps/dt differs; the mixed-control tolerance is 1e-9 K ~ 3e-7 peak)
    off = np.max(np.abs(drive("cscm", BASE, path, strain=strain, n_steps=300,
                              rate=1000.0)["y"]))
    assert off == pytest.approx(static, rel=1e-6)
    peaks = [np.max(np.abs(drive("cscm", {**BASE, "rate_effects": True}, path,
                                 strain=strain, n_steps=300, rate=r)["y"]))
             for r in rates]
    assert peaks[0] > static * 1.01
    assert all(b > a for a, b in zip(peaks, peaks[1:]))
    # overstress bound: |s_vp - s_P| <= OVER and the inviscid stress is at
    # most the shear-surface strength (tension: the static f_ut, no cap).
    # Not strict: the total lateral stress is zero, so the inviscid part
    # carries the lateral overstress with opposite sign (a small confinement
    # of s_P, which raises its axial strength); measured excess 0.1 % with
    # the rate-enhanced damage thresholds, hence 1 %.
    bound = (_shear_only_uc(p) if path == "uniaxial-compression" else static) \
        + p[cscm.P_OVERC]
    assert max(peaks) <= bound * 1.01


# --------------------------------------------------------------------------
# Robustness
# --------------------------------------------------------------------------


@pytest.mark.parametrize("path, strain, probes", [
    ("uniaxial-compression", 0.01, (0.002, 0.004, 0.008)),
    ("uniaxial-tension", 0.03, (0.0005, 0.001, 0.003)),
])
def test_ten_times_larger_increments_agree(path, strain, probes):
    # stress at fixed strains and the fracture energy within 1 % (of the
    # peak stress / of GF) between 2000 and 200 driver steps.
    fine = drive("cscm", BASE, path, strain=strain, n_steps=2000)
    coarse = drive("cscm", BASE, path, strain=strain, n_steps=200)
    peak = np.max(np.abs(fine["y"]))
    for e in probes:
        a = np.interp(e, np.abs(fine["x"]), np.abs(fine["y"]))
        b = np.interp(e, np.abs(coarse["x"]), np.abs(coarse["y"]))
        assert abs(a - b) < 0.01 * peak
    assert post_peak_area(coarse) == pytest.approx(post_peak_area(fine), rel=0.01)


@pytest.mark.parametrize("path", ["uniaxial-compression", "uniaxial-tension",
                                  "hydrostatic", "triaxial", "shear", "cyclic"])
def test_no_nan_on_any_path(path):
    strain = {"uniaxial-compression": 0.05, "uniaxial-tension": 0.05,
              "hydrostatic": 0.2, "triaxial": 0.05, "shear": 0.05, "cyclic": 0.05}[path]
    for extra in ({}, {"rate_effects": True}):
        res = drive("cscm", {**BASE, **extra}, path, strain=strain, n_steps=300,
                    confinement=10e6, rate=100.0)
        for key in ("stress", "strain", "damage", "history"):
            assert np.all(np.isfinite(res[key])), key
        assert np.all((res["damage"] >= 0) & (res["damage"] <= 1))
    if path in ("uniaxial-compression", "uniaxial-tension"):
        assert res["damage"][-1] > 0.99   # full damage reached


def test_triaxial_confinement_raises_strength():
    # notes sec. 2.4: first yield at 10 MPa confinement TXC@10 = 56.905 MPa
    # (axial stress); 0.5 % (driver step). Unconfined: 42.53.
    res = drive("cscm", BASE, "triaxial", strain=0.004, n_steps=400, confinement=10e6)
    s = res["stress"]
    assert np.allclose(s[-1, 1:3], -10e6, atol=1e-3 * 10e6)
    ax = -s[:, 0]
    i = int(np.argmax(res["history"][:, 1] != 0))  # first plastic sample
    assert ax[i] == pytest.approx(56.905e6, rel=5e-3)


def test_recovery_and_erosion():
    # brittle damage from tension is recovered in compression with RECOV = 0
    # (modulus back), kept with RECOV = 1 (notes sec. 1.9 RECOV text).
    m = get_model("cscm")
    out = {}
    for recov in (0.0, 1.0):
        p = cscm.pack_cscm({**BASE, "recovery": recov})
        h = m.initial_history(p)
        for _ in range(500):   # uniaxial strain in tension to heavy damage
            s, d = cscm.cscm_point(h, (2e-5, 0, 0, 0, 0, 0), 1.0, p, 0.01)
        assert d > 0.9
        for _ in range(12):   # unload into (elastic) compression
            s, d = cscm.cscm_point(h, (-2e-5, 0, 0, 0, 0, 0), 1.0, p, 0.01)
        out[recov] = (s, d)
    assert out[0.0][1] < 0.05 and out[1.0][1] > 0.9
    # erosion: failed point keeps no deviatoric / tensile stress
    p = cscm.pack_cscm({**BASE, "erode": True, "erode_strain": 0.01})
    h = m.initial_history(p)
    for _ in range(2000):
        s, d = cscm.cscm_point(h, (2e-5, 0, 0, 0, 0, 0), 1.0, p, 0.01)
    assert h[cscm.H_ERODED] == 1.0 and d == 1.0 and s == (0, 0, 0, 0, 0, 0)
    s, d = cscm.cscm_point(h, (-0.1, -0.1, -0.1, 1e-3, 0, 0), 1.0, p, 0.01)
    assert s[0] < 0 and s[0] == s[1] == s[2] and s[3] == 0.0


def group_run(p):
    """Three points of the CSCM group kernel strained along x at rates 2e-4
    (tension), -3e-3 (compression) and 1e-6 /s for ten steps of 1 s, no spin:
    (sig, damage, hist, e, c)."""
    m = get_model("cscm")
    n = 3
    hist = np.tile(m.initial_history(p), (n, 1))
    sig, L = np.zeros((n, 3, 3)), np.zeros((n, 3, 3))
    L[:, 0, 0] = [2e-4, -3e-3, 1e-6]
    rho = np.full(n, 2400.0)
    e, c, dmg = np.zeros(n), np.zeros(n), np.zeros(n)
    for _ in range(10):
        m.update(np.arange(n), L, 1.0, rho, sig, e, c, dmg, hist, p, np.full(n, 0.01))
    return sig, dmg, hist, e, c


def test_group_kernel_matches_point_function_and_wave_speed():
    # kernel with zero spin = point function; c from the damaged moduli.
    m = get_model("cscm")
    p = m.pack(BASE)
    sig, dmg, hist, e, c = group_run(p)
    h = m.initial_history(p)
    for _ in range(10):  # the first point's strain rate 2e-4 /s over 1 s
        s, d = cscm.cscm_point(h, (2e-4, 0, 0, 0, 0, 0), 1.0, p, 0.01)
    assert np.allclose(hist[0], h, rtol=1e-12, atol=0)
    assert sig[0, 0, 0] == pytest.approx(s[0], rel=1e-12)
    assert dmg[0] > 0.5 and dmg[2] == 0.0
    K, G = p[1], p[2]
    assert c[0] == pytest.approx(math.sqrt((1 - dmg[0]) * (K + 4 * G / 3) / 2400), rel=1e-12)
    assert c[2] == pytest.approx(math.sqrt((K + 4 * G / 3) / 2400), rel=1e-12)


def test_undamaged_wave_speed_switch_changes_the_wave_speed_only():
    # wave_speed = "undamaged": c = sqrt((K + 4G/3)/rho) also where damage is
    # 0.48-0.55 (tension, compression; LS-DYNA's constant moduli of a user
    # material), the stress, damage and history bit for bit those of the
    # default (damaged) run.
    m = get_model("cscm")
    runs = []
    for switch in ("damaged", "undamaged"):
        p = m.pack({**BASE, "wave_speed": switch})
        runs.append(group_run(p))
    for a, b in zip(runs[0][:4], runs[1][:4]):
        assert np.array_equal(a, b)
    K, G = p[1], p[2]
    dmg, c = runs[1][1], runs[1][4]
    assert dmg[0] > 0.5 and dmg[1] > 0.4
    assert np.array_equal(c, np.full(3, math.sqrt((K + 4 * G / 3) / 2400)))
    assert runs[0][4][0] == pytest.approx(math.sqrt((1 - dmg[0]) * (K + 4 * G / 3) / 2400),
                                          rel=1e-12)
    with pytest.raises(ValueError, match="wave_speed"):
        m.pack({**BASE, "wave_speed": "elastic"})


@pytest.mark.parametrize("bhat", [-math.pi / 6, 0.1, math.pi / 6])
def test_meridian_slope_and_curvature_are_the_derivatives_of_the_meridian(bhat):
    # meridian_radius_curvature: the value bit for bit that of
    # meridian_radius (value and slope those of meridian_radius_slope), the
    # slope against a central difference of the value and the curvature
    # against one of the slope (step 1e-4 of |J1| + alpha: truncation
    # ~h^2 F''', round-off ~eps F / h, both below 1e-6 of the slope's scale
    # and 1e-5 of the curvature) on the tensile part (Rubin ratios held,
    # J1 < 0), the shear part (J1 in (0, L)) and the cap (L, X), with a
    # hardened cap.
    p = packed()
    kappa = 60e6
    m = cscm.meridian(bhat, kappa, p)
    L, X = m[2], m[3]
    apex = p[cscm.P_J1APEX]
    points = np.concatenate([np.linspace(apex, 0, 12)[1:-1], np.linspace(0, L, 12)[1:-1],
                             np.linspace(L, X, 12)[1:-2]])
    scale = cscm.shear_surface(0.0, p) / abs(apex)
    for J1 in points:
        F, dF, d2F = cscm.meridian_radius_curvature(J1, m, p)
        assert F == cscm.meridian_radius(J1, m, p)
        assert (F, dF) == cscm.meridian_radius_slope(J1, m, p)
        h = 1e-4 * (abs(J1) + p[cscm.P_ALPHA])
        fd = (cscm.meridian_radius(J1 + h, m, p) - cscm.meridian_radius(J1 - h, m, p)) / (2 * h)
        assert dF == pytest.approx(fd, rel=1e-6, abs=1e-6 * scale)
        fd2 = (cscm.meridian_radius_slope(J1 + h, m, p)[1]
               - cscm.meridian_radius_slope(J1 - h, m, p)[1]) / (2 * h)
        assert d2F == pytest.approx(fd2, rel=1e-5, abs=1e-6 * scale / abs(apex))
    assert cscm.meridian_radius_curvature(apex - 1.0, m, p) == (0.0, 0.0, 0.0)
    assert cscm.meridian_radius_curvature(X + 1.0, m, p) == (0.0, 0.0, 0.0)


def test_sure_elastic_test_never_passes_a_yielding_stress():
    # surely_elastic() skips the full yield check. Its bound needs the Rubin
    # factor >= min(Q1, Q2, 1) at every Lode angle: checked on a grid of
    # angles over the fits' Q1, Q2 from J1 = -10 to 300 MPa. Then 20,000
    # random stresses (pressures from tension beyond the apex to beyond the
    # cap, deviators up to 1.5 x the surface, initial and hardened caps):
    # whenever it says elastic, yield_function() <= 0; and it does say so
    # for most states well inside (a test that cannot pass by saying False).
    p = packed()
    beta = np.linspace(-math.pi / 6, math.pi / 6, 61)
    for J1 in np.linspace(-10e6, 300e6, 40):
        q1, q2 = cscm.rubin_q(J1, p)
        rub = [cscm.rubin_factor(q1, q2, b) for b in beta]
        assert min(rub) >= min(q1, q2, 1.0) * (1 - 1e-12)
    rng = np.random.default_rng(11)
    said = inside = 0
    for kappa in (cscm.kappa0(p), 60e6):
        X = cscm.cap_function(0.0, kappa, p)[1]
        for _ in range(10000):
            J1 = rng.uniform(p[cscm.P_J1APEX] - 5e6, X + 10e6)
            dev = rng.normal(size=6)
            dev[:3] -= dev[:3].mean()
            nrm = math.sqrt(0.5 * (dev[:3] @ dev[:3]) + dev[3:] @ dev[3:])
            r = rng.uniform(0.0, 1.5) * cscm.shear_surface(max(J1, 0.0), p)
            s = tuple(dev * r / nrm - np.array([J1 / 3] * 3 + [0.0] * 3))
            f = cscm.yield_function(s, kappa, p)
            if cscm.surely_elastic(s, kappa, p):
                said += 1
                assert f <= 0.0
            if f < -0.3 * cscm.shear_surface(max(J1, 0.0), p) ** 2 and 0 < J1 < kappa:
                inside += 1
    assert inside > 500 and said > 0.8 * inside


def test_max_principal_and_its_bound():
    # max_principal() against numpy's eigenvalues (1e-12 of the tensor's
    # size: the trigonometric formula loses a few digits near equal
    # eigenvalues); max_principal_bound() (m + 2 sqrt(J2/3), which lets the
    # damage update skip asin and cos where tau_t cannot rise) is never below
    # it, compared exactly in floating point as the update compares it, over
    # 20,000 random strains of sizes 1e-9 to 1e-1; it is attained where the
    # two smaller eigenvalues are equal (cos(pi/6 - theta) = 1), and it is
    # not a loose bound elsewhere (within a factor 2 of the deviatoric part).
    rng = np.random.default_rng(5)
    for _ in range(20000):
        e = rng.normal(size=6) * 10.0 ** rng.uniform(-9, -1)
        t = np.array([[e[0], e[3], e[5]], [e[3], e[1], e[4]], [e[5], e[4], e[2]]])
        lam = np.linalg.eigvalsh(t)
        size = np.abs(lam).max()
        e1 = cscm.max_principal(tuple(e))
        assert abs(e1 - lam[-1]) <= 1e-12 * size
        ub = cscm.max_principal_bound(tuple(e))
        assert ub >= e1
        m = lam.mean()
        assert ub - m <= 2.0 * (lam[-1] - m) + 1e-12 * size
    for a, b in ((3e-3, -1e-3), (-2e-4, -5e-4), (1.0, 1.0)):
        e = (a, b, b, 0.0, 0.0, 0.0)
        assert cscm.max_principal_bound(e) == pytest.approx(max(a, b), rel=1e-14)


def test_pressure_free_elastic_bound():
    # surely_elastic() first compares sqrt(J2') with P_R0_ELASTIC for J1 >= 0
    # (no exponentials). (1) The bound is its formula, 0.999 min(Q1(0), Q2(0), 1)
    # Ff(0), written out from the parameters (a wrong factor fails here).
    # (2) It is sufficient: 20,000 random stresses with 0 <= J1 <= L and
    # sqrt(J2') up to 1.5 r0 (three fc, initial and hardened caps): every one
    # below r0 is also elastic by the exponential test alone (the bound
    # switched off) and by yield_function, so the decisions, and the
    # results, are those of the test without it. (3) A surface that may
    # decrease with J1 gets no bound: theta < 0, and the default fits at
    # fc = 80 MPa (their Q1, Q2 have beta_i < 0 and theta_i < 0).
    for fc in (20e6, 43.1e6):
        p = packed(fc=fc)
        r0 = 0.999 * min(p[cscm.P_A1] - p[cscm.P_L1], p[cscm.P_A2] - p[cscm.P_L2], 1.0) * (
            p[cscm.P_ALPHA] - p[cscm.P_LAMDA])
        assert p[cscm.P_R0_ELASTIC] == pytest.approx(r0, rel=1e-14) and r0 > 0.1 * fc / 43.1
        off = p.copy()
        off[cscm.P_R0_ELASTIC] = 0.0
        rng = np.random.default_rng(5)
        below = 0
        for kappa in (cscm.kappa0(p), 60e6):
            for _ in range(10000):
                J1 = rng.uniform(0.0, max(kappa, cscm.kappa0(p)))
                dev = rng.normal(size=6)
                dev[:3] -= dev[:3].mean()
                nrm = math.sqrt(0.5 * (dev[:3] @ dev[:3]) + dev[3:] @ dev[3:])
                r = rng.uniform(0.0, 1.5) * r0
                s = tuple(dev * r / nrm - np.array([J1 / 3] * 3 + [0.0] * 3))
                if r < r0:
                    below += 1
                    assert cscm.surely_elastic(s, kappa, p)
                    assert cscm.surely_elastic(s, kappa, off)
                    assert cscm.yield_function(s, kappa, p) <= 0.0
        assert below > 10000
    assert packed(theta=-1e-3)[cscm.P_R0_ELASTIC] == 0.0
    assert packed(fc=80e6)[cscm.P_R0_ELASTIC] == 0.0


def test_fast_return_equals_global_closest_point():
    # project() takes a local bracketing path when the trial lies above the
    # meridian or in tension beyond the apex; it must find the same closest
    # point as the global scan + golden-section search of project_global()
    # (and never a worse one). 1500 random trials: tension (a third beyond
    # the apex, down to 30 MPa below it: the disc's tensile failures reach
    # 20 MPa), shear, compression up to beyond the cap, three Lode angles,
    # initial and hardened caps. Tolerance 1e-6 of the surface extent in J1
    # (the golden bracket + refinement reach ~1e-9).
    p = packed()
    K, G = p[cscm.P_K], p[cscm.P_G]
    rng = np.random.default_rng(7)
    k0 = cscm.kappa0(p)
    checked = 0
    for kappa in (k0, 60e6, 150e6):
        X = cscm.cap_function(0.0, kappa, p)[1]
        ext = X - p[cscm.P_J1APEX]
        for _ in range(500):
            J1t = rng.uniform(p[cscm.P_J1APEX] - 5e6, X + 20e6)
            if checked % 3 == 0:
                J1t = p[cscm.P_J1APEX] - rng.uniform(0.0, 30e6)
            bhat = rng.choice([-math.pi / 6, 0.0, math.pi / 6]) * rng.uniform(0.2, 1.0)
            rt = rng.uniform(0.0, 2.0) * cscm.shear_surface(max(J1t, 0.0), p)
            if J1t < p[cscm.P_J1APEX]:
                rt = rng.uniform(0.0, 3.0) * cscm.shear_surface(0.0, p)
            fast = cscm.project(J1t, rt, bhat, kappa, K, G, p)
            glob = cscm.project_global(J1t, rt, bhat, kappa, K, G, p)
            phi = [(j - J1t) ** 2 / (9 * K) + (r - rt) ** 2 / G for j, r in (fast, glob)]
            assert phi[0] <= phi[1] * (1 + 1e-9) + 1e-30
            assert abs(fast[0] - glob[0]) < 1e-6 * ext
            assert abs(fast[1] - glob[1]) < 1e-6 * ext
            checked += 1
    assert checked == 1500


def test_return_near_the_kink_takes_the_nearer_piece():
    # The meridian has a convex kink at J1 = 0 (the Rubin ratios start to
    # vary), so for a trial with J1_apex < J1t < 0 above the meridian phi may
    # have a minimum on each side of it. The return takes the nearer of the
    # two (Newton on the trial's piece, _piece_minimum right of the kink):
    # 3000 trials there (rt up to e x F(J1t), three caps, any Lode angle)
    # reach the global search's distance to 1e-9. The return before
    # 2026-11-27 (one bracketing search across the kink) was farther on
    # some (0.03-18 % in phi; this test fails on it).
    p = packed()
    K, G = p[cscm.P_K], p[cscm.P_G]
    rng = np.random.default_rng(9)
    apex = p[cscm.P_J1APEX]
    for kappa in (cscm.kappa0(p), 60e6, 150e6):
        for _ in range(1000):
            bhat = rng.uniform(-math.pi / 6, math.pi / 6)
            J1t = rng.uniform(apex, 0.0)
            m = cscm.meridian(bhat, kappa, p)
            rt = cscm.meridian_radius(J1t, m, p) * math.exp(rng.uniform(0.0, 1.0))
            phi = [(j - J1t) ** 2 / (9 * K) + (r - rt) ** 2 / G
                   for j, r in (cscm.project(J1t, rt, bhat, kappa, K, G, p),
                                cscm.project_global(J1t, rt, bhat, kappa, K, G, p))]
            assert phi[0] <= phi[1] * (1 + 1e-9) + 1e-30


def test_newton_return_equals_the_bracketing_one():
    # The fast path's Newton iteration (exact curvature of the meridian) must
    # land on the root of dphi/dJ1 that the bracketing search + regula falsi
    # finds, to the tolerance both stop at (1e-11 (|J1t| + alpha) each, so
    # 2.5e-11 here), with F the meridian's value there: bit for bit where
    # the last point was evaluated, to 1e-12 of F where the iteration stops
    # on the predicted next step and takes F's second-order Taylor value
    # (its remainder F''' s^3/6 is at most 6e-13 of F over 15000 trials; a
    # first-order value is off by up to 1e-10, a step taken from the trial's
    # first step by 2e-9 in J1); and it must converge by itself (not hand
    # over to the bracketing search) for nearly all trials above the
    # meridian: 1000 random ones (shear and cap sides, three Lode angles,
    # initial and hardened caps).
    from sphdyn.materials.cscm import projection as proj
    p = packed()
    K, G = p[cscm.P_K], p[cscm.P_G]
    rng = np.random.default_rng(3)
    apex = p[cscm.P_J1APEX]
    converged = tried = 0
    for kappa in (cscm.kappa0(p), 60e6):
        for _ in range(500):
            bhat = rng.uniform(-math.pi / 6, math.pi / 6)
            m = cscm.meridian(bhat, kappa, p)
            J1t = rng.uniform(apex, m[3])
            Ft = cscm.meridian_radius(J1t, m, p)
            rt = Ft * rng.uniform(1.001, 2.0)
            g0, gp0, F0, dF0 = proj._dphi_curvature(J1t, J1t, rt, m, K, G, p)
            if not Ft > 0.0 or g0 == 0.0:
                continue
            tried += 1
            J1n, Fn = proj._newton(J1t, g0, gp0, F0, apex, m[3], J1t, rt, m, K, G, p)
            J1b = proj._bracket(J1t, g0, dF0, apex, m[3], J1t, rt, m, K, G, p)
            if J1n == J1n:
                converged += 1
                assert abs(Fn - cscm.meridian_radius(J1n, m, p)) <= 1e-12 * Fn
                assert abs(J1n - J1b) <= 2.5e-11 * (abs(J1t) + p[cscm.P_ALPHA])
    assert tried > 900 and converged >= 0.99 * tried
    # A trial whose Newton step leaves the bracket, so the iteration bisects
    # (found by an instrumented run: 1 in 9000 random trials over the shear
    # part and the cap, none of the disc's returns): it still converges by
    # itself, to the bracketing search's root.
    kappa, bhat, J1t, rt = 60e6, -0.21428892513936015, 2212552.395358473, 36785563.388134934
    m = cscm.meridian(bhat, kappa, p)
    g0, gp0, F0, dF0 = proj._dphi_curvature(J1t, J1t, rt, m, K, G, p)
    J1n, Fn = proj._newton(J1t, g0, gp0, F0, apex, m[3], J1t, rt, m, K, G, p)
    J1b = proj._bracket(J1t, g0, dF0, apex, m[3], J1t, rt, m, K, G, p)
    assert J1n == J1n and abs(Fn - cscm.meridian_radius(J1n, m, p)) <= 1e-12 * Fn
    assert abs(J1n - J1b) <= 2.5e-11 * (abs(J1t) + p[cscm.P_ALPHA])
    # A trial on the cap whose first step (from the trial, far from Newton's
    # asymptotic rate) and second would predict the third below the
    # tolerance: taken, it is 2.6 tolerances off (found among 60000 random
    # trials, with 12 others); the prediction waits for two steps after it.
    kappa, bhat, J1t, rt = 150e6, -0.07399259727426066, 291963076.8399167, 150471087.08924875
    m = cscm.meridian(bhat, kappa, p)
    g0, gp0, F0, dF0 = proj._dphi_curvature(J1t, J1t, rt, m, K, G, p)
    J1n, Fn = proj._newton(J1t, g0, gp0, F0, apex, m[3], J1t, rt, m, K, G, p)
    J1b = proj._bracket(J1t, g0, dF0, apex, m[3], J1t, rt, m, K, G, p)
    assert abs(J1n - J1b) <= 2.5e-11 * (abs(J1t) + p[cscm.P_ALPHA])


def test_recovery_option_2_needs_compressive_volume_strain():
    # RECOV 10-11 (notes sec. 1.9 [V] flag text): recovery "based on the sign
    # of both the pressure and the volumetric strain". After tensile failure
    # in uniaxial strain (eps = 1 %), a small compressive unloading makes the
    # pressure compressive while the volume strain is still tensile: option
    # 1 (RECOV = 0) recovers the modulus, option 2 (RECOV = 10) keeps the
    # brittle damage; once the volume strain is compressive both recover.
    # Thresholds 0.05 / 0.9: the states are d = 0 and d = 0.986.
    m = get_model("cscm")
    out = {}
    for recov in (0.0, 10.0):
        p = cscm.pack_cscm({**BASE, "recovery": recov})
        h = m.initial_history(p)
        for _ in range(500):
            cscm.cscm_point(h, (2e-5, 0, 0, 0, 0, 0), 1.0, p, 0.01)
        for _ in range(12):
            s1, d1 = cscm.cscm_point(h, (-2e-5, 0, 0, 0, 0, 0), 1.0, p, 0.01)
        assert s1[0] < 0 and sum(h[cscm.H_EPS:cscm.H_EPS + 3]) > 0
        for _ in range(12):
            s2, d2 = cscm.cscm_point(h, (-1e-3, 0, 0, 0, 0, 0), 1.0, p, 0.01)
        assert s2[0] < 0 and sum(h[cscm.H_EPS:cscm.H_EPS + 3]) < 0
        out[recov] = (d1, d2)
    assert out[0.0][0] < 0.05 and out[10.0][0] > 0.9
    assert out[0.0][1] < 0.1 and out[10.0][1] == pytest.approx(out[0.0][1], abs=1e-12)
    with pytest.raises(ValueError, match="recovery"):
        cscm.pack_cscm({**BASE, "recovery": 5.0})


@pytest.mark.parametrize("retract", [False, True])
def test_cap_retraction(retract):
    # ITRETRC (notes sec. 1.3 [V flag], mechanism [R/D]): hydrostatic
    # compaction to ~114 MPa moves the cap out (kappa ~ 100 MPa); dilation
    # under hydrostatic tension then reduces the plastic volume compaction
    # below zero. Without retraction the cap stays (kappa unchanged, exact);
    # with retraction it follows X(ev) and stops at the initial cap X0
    # (kappa = kappa0 to the Newton tolerance, 1e-9 relative).
    m = get_model("cscm")
    p = cscm.pack_cscm({**BASE, "cap_retraction": retract})
    h = m.initial_history(p)
    for _ in range(400):
        cscm.cscm_point(h, (-1e-5, -1e-5, -1e-5, 0, 0, 0), 1.0, p, 0.01)
    k_hard = h[cscm.H_KAPPA]
    assert k_hard > 4 * cscm.kappa0(p) and h[cscm.H_EV] > 0.003
    X_hard = cscm.cap_function(0.0, k_hard, p)[1]
    assert X_hard == pytest.approx(cscm.cap_from_compaction(h[cscm.H_EV], p), rel=1e-3)
    for _ in range(3000):
        s, d = cscm.cscm_point(h, (1e-5, 1e-5, 1e-5, 0, 0, 0), 1.0, p, 0.01)
    assert h[cscm.H_EV] < 0.0
    if retract:
        assert h[cscm.H_KAPPA] == pytest.approx(cscm.kappa0(p), rel=1e-9)
    else:
        assert h[cscm.H_KAPPA] == k_hard


def test_rate_enhanced_damage_thresholds():
    # choice [D] (docs/cscm.md): with rate effects the damage thresholds are
    # r0 x (largest dynamic-to-static strength ratio), so in uniaxial tension
    # at 100/s the stress at which damage reaches 1 % is well above the
    # static tensile strength (f_ut = 3.107 MPa; measured 1.79 f_ut), while
    # without the scaling it is close to it (measured 1.26 f_ut). Without
    # rate effects the switch changes nothing (bitwise).
    ft = 3.107e6
    onset = {}
    for rt in (False, True):
        r = drive("cscm", {**BASE, "rate_effects": True, "rate_thresholds": rt},
                  "uniaxial-tension", strain=0.002, n_steps=300, rate=100.0)
        j = int(np.argmax(r["damage"] > 1e-2))
        onset[rt] = abs(r["y"][j])
        assert np.all(r["history"][:, cscm.H_RFMAX] >= 1.0)
    assert onset[False] < 1.35 * ft
    assert onset[True] > 1.6 * ft
    a = drive("cscm", {**BASE, "rate_thresholds": False}, "uniaxial-tension",
              strain=0.002, n_steps=100)
    b = drive("cscm", BASE, "uniaxial-tension", strain=0.002, n_steps=100)
    assert np.array_equal(a["stress"], b["stress"])


def test_power_skips_pow_only_for_the_exponent_one():
    # damage.power: x ** e, with e == 1 (the default pwrt and repow) returned
    # as x (pow is within 0.52 ulp of the representable x: the same bits);
    # any other exponent is pow's (the transition with pwrc = 5 and 0.7)
    from sphdyn.materials.cscm.damage import power, transition
    for x in (0.0, 0.3, 0.7071067811865476, 1.0, 2.5):
        assert power(x, 1.0) == x ** 1.0 == x
        assert power(x, 5.0) == x ** 5.0
        assert power(x, 0.7) == x ** 0.7
    r = 1e6
    J1 = 0.6 * math.sqrt(3.0) * r
    assert transition(J1, r, 1.0) == pytest.approx(0.6, rel=1e-15)
    assert transition(J1, r, 5.0) == pytest.approx(0.6 ** 5, rel=1e-14)
    assert transition(-J1, r, 0.7) == pytest.approx(0.6 ** 0.7, rel=1e-14)


def test_fracture_energy_grows_with_rate_by_repow():
    # notes sec. 1.10 [V name, R form]: with rate effects the softening's GF
    # is multiplied by rf^REPOW (rf the dynamic-to-static strength ratio).
    # (1) damage_scale is that formula (and 1 without rate effects), exactly;
    # (2) in uniaxial tension at 100/s to 0.3 % strain (rf reaches 2.9),
    # REPOW 0, 1, 2 leave less and less damage (measured 0.97, 0.70, 0.33): a
    # missing or constant scale would give three equal values.
    for repow in (0.0, 1.0, 2.0):
        p = packed(rate_effects=True, repow=repow)
        assert cscm.damage_scale(1.7, True, p) == 1.7 ** repow
        assert cscm.damage_scale(1.7, False, p) == 1.0
    final = [drive("cscm", {**BASE, "rate_effects": True, "repow": repow},
                   "uniaxial-tension", strain=0.003, n_steps=600, rate=100.0)["damage"][-1]
             for repow in (0.0, 1.0, 2.0)]
    assert final[0] > final[1] + 0.1 > final[2] + 0.2


def test_deck_keys_reach_the_parameters():
    # [[material]] cap_retraction, rate_thresholds and recovery 10-11 (RECOV
    # option 2) are packed into the parameter vector of the model.
    from pathlib import Path

    from sphdyn.deck import DeckError, loads_deck
    from sphdyn.materials import cscm as mod
    from sphdyn.build.model import build_model

    base = (Path(__file__).parent.parent / "examples/disc_impact.toml").read_text()
    # (the deck sets rate_thresholds = true, marked calibrated; the default is false)
    text = base.replace('model = "cscm"', 'model = "cscm"\ncap_retraction = true\n'
                        'recovery = 10.5').replace("rate_thresholds = true",
                                                   "rate_thresholds = false")
    g = build_model(loads_deck(text)).groups[0]
    assert g.params[mod.P_RETRACT] == 1.0
    assert g.params[mod.P_RECOV] == 0.5 and g.params[mod.P_RECOV_VOL] == 1.0
    g0 = build_model(loads_deck(base)).groups[0]
    assert g0.params[mod.P_RETRACT] == 0.0 and g0.params[mod.P_RECOV_VOL] == 0.0
    assert g.params[mod.P_RATE_R0] == 0.0 and g0.params[mod.P_RATE_R0] == 1.0
    with pytest.raises(DeckError, match="recovery"):
        loads_deck(base.replace('model = "cscm"', 'model = "cscm"\nrecovery = 5'))
    g = build_model(loads_deck(base.replace('model = "cscm"', 'model = "cscm"\n'
                                            'wave_speed = "undamaged"'))).groups[0]
    assert g.params[mod.P_WAVE_UNDAMAGED] == 1.0 and g0.params[mod.P_WAVE_UNDAMAGED] == 0.0
    with pytest.raises(DeckError, match="wave_speed"):
        loads_deck(base.replace('model = "cscm"', 'model = "cscm"\nwave_speed = "elastic"'))
    g = build_model(loads_deck(base.replace('model = "cscm"', 'model = "cscm"\n'
                                            'damage_growth = "state"'))).groups[0]
    assert g.params[mod.P_GROW_ON_LOADING] == 0.0 and g0.params[mod.P_GROW_ON_LOADING] == 1.0
    with pytest.raises(DeckError, match="damage_growth"):
        loads_deck(base.replace('model = "cscm"', 'model = "cscm"\ndamage_growth = "always"'))


def test_damage_growth_on_loading_only_keeps_the_damage_in_unloading():
    """``damage_growth``: compressed past the ductile threshold (300 steps of
    -2e-5 along x with +0.4e-5 across: about -71 MPa, ductile damage 0.19),
    then unloaded (3000 steps of +2e-6 along x and -0.4e-6 across: the
    axial stress falls to a few MPa of tension while the lateral stress
    stays near -40 MPa, so |J1| / sqrt(3 J2') falls towards the shear
    side): tau_c never passes its largest value again in either. With
    "loading" (the default) the damage is exactly what it was; with "state"
    it is evaluated at every step with the softening rate of the current,
    more shear-like state and grows while the point unloads (by 0.03 here;
    at least 0.01 asked). The loaded states are identical."""
    m = get_model("cscm")
    out = {}
    for growth in ("state", "loading"):
        p = packed(damage_growth=growth)
        assert p[cscm.P_GROW_ON_LOADING] == (1.0 if growth == "loading" else 0.0)
        h = m.initial_history(p)
        for _ in range(300):
            cscm.cscm_point(h, (-2e-5, 0.4e-5, 0.4e-5, 0, 0, 0), 1.0, p, 0.01)
        loaded = (h[cscm.H_DD], h[cscm.H_TC])
        for _ in range(3000):
            s, _ = cscm.cscm_point(h, (2e-6, -0.4e-6, -0.4e-6, 0, 0, 0), 1.0, p, 0.01)
        assert s[0] > 0.0 and -(s[0] + s[1] + s[2]) > 0.0  # still in the ductile branch
        assert h[cscm.H_TC] == loaded[1]
        out[growth] = (loaded[0], h[cscm.H_DD])
    assert out["state"][0] == out["loading"][0] and 0.1 < out["loading"][0] < 0.3
    assert out["loading"][1] == out["loading"][0]
    assert out["state"][1] > out["state"][0] + 0.01
    with pytest.raises(ValueError, match="damage_growth"):
        packed(damage_growth="always")
    # the default is the loading condition (docs/cscm.md, 3a)
    assert packed()[cscm.P_GROW_ON_LOADING] == 1.0
