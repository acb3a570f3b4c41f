"""High explosive (JWL, programmed and beta burn) and gas materials: the
equations of state against their formulas, the TNT preset's Chapman-Jouguet
state, the burn, the energy books, a 1D detonation and Sod's shock tube
against the exact solution, and the deck's checks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sphdyn.analysis.riemann import sample, shock_speed
from pathlib import Path

import tomli_w

from sphdyn.deck import DeckError, loads_deck
from sphdyn.build.detonation import lighting_times
from sphdyn.kernels import KernelContext
from sphdyn.materials import MaterialGroup, get_model
from sphdyn.materials.eos import (cj_state, jwl_hugoniot_pressure, jwl_pressure,
                                  jwl_sound_speed, polynomial_pressure,
                                  polynomial_sound_speed)
from sphdyn.materials.explosive import H_BURN, H_CLOCK, TNT, burn_fraction
from sphdyn.materials.fluid import fluid_energy
from sphdyn.parts import SPHPart, SPHSettings
from sphdyn.state import BC_FIXED, Particles
from sphdyn.stepper import Stepper

JWL = tuple(TNT[k] for k in ("A", "B", "R1", "R2", "omega"))


# ------------------------------------------------------------------ EOS
def test_jwl_pressure_is_the_formula_written_out():
    A, B, R1, R2, w = JWL
    for V, E in [(0.7, 8e9), (1.0, 7e9), (3.0, 1e9)]:
        expect = (A * (1 - w / (R1 * V)) * math.exp(-R1 * V)
                  + B * (1 - w / (R2 * V)) * math.exp(-R2 * V) + w * E / V)
        assert jwl_pressure(V, E, *JWL) == pytest.approx(expect, rel=1e-14)


def _isentrope_c2(pressure, rho, e, d=1e-6):
    """c^2 = dp/drho along de = p drho / rho^2 (central difference)."""
    p = pressure(rho, e)
    dr = d * rho
    up = pressure(rho + dr, e + p * dr / rho ** 2)
    dn = pressure(rho - dr, e - p * dr / rho ** 2)
    return (up - dn) / (2 * dr)


@pytest.mark.parametrize("V,e", [(0.73, 5e6), (1.0, 4.3e6), (2.5, 1e6)])
def test_jwl_sound_speed_is_the_isentrope_slope(V, e):
    # central differences with a relative step of 1e-6: truncation ~1e-12,
    # round-off ~1e-10 of c^2; 1e-7 leaves a wide margin
    rho0 = TNT["density"]

    def pressure(rho, e_):
        return jwl_pressure(rho0 / rho, rho0 * e_, *JWL)

    rho = rho0 / V
    c = jwl_sound_speed(rho, V, rho0 * e, *JWL)
    assert c ** 2 == pytest.approx(_isentrope_c2(pressure, rho, e), rel=1e-7)


def test_tnt_preset_chapman_jouguet_state():
    # the Rayleigh line p = rho0 D^2 (1 - V) touches the Hugoniot from the
    # unreacted state at P_CJ = 21.0 GPa (1 %) and D = 6930 m/s (1 %)
    rho0 = TNT["density"]
    V, p, D = cj_state(*JWL, TNT["E0"], rho0)
    assert p == pytest.approx(21.0e9, rel=0.01)
    assert D == pytest.approx(6930.0, rel=0.01)
    assert p == pytest.approx(rho0 * D ** 2 * (1 - V), rel=1e-12)  # Rayleigh line
    # Hugoniot: E = E0 + p (1 - V)/2 gives this pressure through the JWL
    E = TNT["E0"] + 0.5 * p * (1 - V)
    assert jwl_pressure(V, E, *JWL) == pytest.approx(p, rel=1e-12)
    # tangency: neighbouring Hugoniot points need a faster detonation
    for dv in (-0.02, 0.02):
        ph = jwl_hugoniot_pressure(V + dv, *JWL, TNT["E0"])
        assert ph / (rho0 * (1 - V - dv)) > D ** 2
    # and V_CJ of the preset's P_CJ and D (Rayleigh line) is that V (1 %)
    assert 1 - TNT["P_CJ"] / (rho0 * TNT["D"] ** 2) == pytest.approx(V, rel=0.01)


C_AIR = (0.0, 0.0, 0.0, 0.0, 0.4, 0.4, 0.0)


def test_ideal_gas_is_the_polynomial_with_c4_c5_gamma_minus_one():
    rho0, rho, e = 1.225, 2.0, 2.5e5
    p = polynomial_pressure(rho / rho0 - 1, rho0 * e, *C_AIR)
    assert p == pytest.approx(0.4 * rho * e, rel=1e-14)
    c = polynomial_sound_speed(rho, rho0, rho0 * e, *C_AIR)
    assert c ** 2 == pytest.approx(1.4 * p / rho, rel=1e-13)


def test_polynomial_drops_c2_c6_in_tension_and_its_sound_speed_is_the_slope():
    C = (1e5, 2.2e9, 9.5e9, 1.5e10, 0.28, 0.28, 0.1)  # water-like
    rho0 = 1000.0
    mu, E = -0.01, 1e5
    assert polynomial_pressure(mu, E, *C) == pytest.approx(
        C[0] + C[1] * mu + C[3] * mu ** 3 + (C[4] + C[5] * mu) * E, rel=1e-14)
    mu = 0.02
    assert polynomial_pressure(mu, E, *C) == pytest.approx(
        C[0] + C[1] * mu + C[2] * mu ** 2 + C[3] * mu ** 3
        + (C[4] + C[5] * mu + C[6] * mu ** 2) * E, rel=1e-14)
    for rho in (990.0, 1020.0):
        def pressure(r, e_):
            return polynomial_pressure(r / rho0 - 1, rho0 * e_, *C)
        c = polynomial_sound_speed(rho, rho0, E, *C)
        assert c ** 2 == pytest.approx(_isentrope_c2(pressure, rho, E / rho0), rel=1e-6)


def test_fluid_energy_solves_its_equation_and_keeps_the_cutoff():
    e_old, dq, p_old, a, b, dt, rho = 1e5, 2e3, 3e8, 1e8, 500.0, 1e-7, 1800.0
    for tr_d in (-2e4, 3e4):
        e, p = fluid_energy(e_old, dq, p_old, a, b, -1e12, tr_d, dt, rho)
        assert p == pytest.approx(a + b * e, rel=1e-14)
        assert e == pytest.approx(e_old + dq - dt * tr_d / (2 * rho) * (p_old + p),
                                  rel=1e-14)
    # a cut pressure: the energy is the work done with it
    e, p = fluid_energy(e_old, 0.0, p_old, -1e9, b, 0.0, 3e4, dt, rho)
    assert p == 0.0
    assert e == pytest.approx(e_old - dt * 3e4 / (2 * rho) * p_old, rel=1e-14)


# ------------------------------------------------------------------ burn
def test_burn_fraction_programmed_beta_and_both():
    D, s, w, Vcj = 6930.0, 1e-3, 1.5, 0.7317
    t = 0.5 * w * s / D  # half way through the front
    assert burn_fraction(0.0, t, 1.0, s, D, Vcj, w, 0) == pytest.approx(0.5, rel=1e-14)
    assert burn_fraction(0.0, -1e-9, 1.0, s, D, Vcj, w, 0) == 0.0  # not lit yet
    assert burn_fraction(0.0, 10 * t, 1.0, s, D, Vcj, w, 0) == 1.0  # clipped
    assert burn_fraction(0.7, t, 1.0, s, D, Vcj, w, 0) == 0.7  # never decreases
    V = 0.9
    beta = (1 - V) / (1 - Vcj)
    assert burn_fraction(0.0, t, V, s, D, Vcj, w, 1) == pytest.approx(beta, rel=1e-14)
    assert burn_fraction(0.0, t, V, s, D, Vcj, w, 0) == pytest.approx(0.5)  # ignores V
    assert burn_fraction(0.0, t, V, s, D, Vcj, w, 2) == pytest.approx(max(0.5, beta))


def test_lighting_times_are_the_nearest_point_over_d():
    x = np.array([[0.0, 0, 0], [0.3, 0.4, 0], [1.0, 0, 0]])
    pts = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    t = lighting_times(x, pts, np.array([0.0, 1e-5]), 5000.0)
    assert np.allclose(t, [0.0, 0.5 / 5000.0, 1e-5], rtol=1e-14)


# ------------------------------------------------------- 1D runs (uniaxial)
def _settings(correction, limits, cfl=0.3):
    return SPHSettings(correction=correction, alpha=1.0, beta=2.0, xsph=0.0, benz=True,
                       h_min_factor=0.1, h_max_factor=20.0, skin_factor=0.2, cfl=cfl,
                       stress_exponent=4.0, epsilon=(0.0,), total_lagrangian=(False,),
                       hourglass_coefficient=0.0, reference_update_every=0, crack_band=2.0,
                       density_limits=limits)


def _particles(x, dx, rho, n_hist):
    n = x.size
    p = Particles.allocate(n, 1, n_hist)
    p.x[:, 0] = x
    p.x0[:] = p.x
    p.vol0[:] = dx
    p.rho[:] = rho
    p.rho0[:] = p.rho
    p.m[:] = p.rho * p.vol0
    p.h[:] = 1.2 * p.vol0
    p.h0[:] = p.h
    return p


def tnt_slab(n=400, length=0.1, burn="both", cfl=0.3):
    """A 1D TNT column of ``n`` particles over ``length`` lit at x = 0."""
    he = get_model("high_explosive")
    prm = he.pack({"preset": "tnt", "burn": burn})
    dx = length / n
    p = _particles((np.arange(n) + 0.5) * dx, dx, prm[0], 2)
    g = MaterialGroup("tnt", he, prm, np.arange(n, dtype=np.int64), 0)
    p.hist[:] = he.initial_history(prm)
    p.hist[:, H_CLOCK] = -lighting_times(p.x, np.zeros((1, 3)), np.zeros(1), TNT["D"])
    p.c[:] = he.wave_speed(prm, prm[0])
    part = SPHPart(p, [g], KernelContext.named("cubic_spline", 1, 1.0),
                   _settings(True, ((1e-3, 5.0),), cfl))
    return Stepper([part]), part


def test_1d_detonation_front_runs_at_d_and_reaches_the_cj_pressure():
    # 400 particles over 0.1 m (dx 0.25 mm): the pressure peak's position
    # over 2-12 us moves at D within 2 % (measured 0.9 % slow) and its value
    # rises to P_CJ (measured 20.3 GPa at 12 us; the front widens over
    # about 3 dx, so the peak stays a few % below P_CJ: 5 % asked)
    st, part = tnt_slab()
    p = part.p
    rows = []
    for t in np.linspace(2e-6, 12e-6, 6):
        while st.t < t:
            st.step(t_stop=t)
        pr = -p.sig[:, 0, 0]
        k = int(np.argmax(pr))
        rows.append((st.t, p.x[k, 0], pr[k]))
    r = np.array(rows)
    speed = np.polyfit(r[:, 0], r[:, 1], 1)[0]
    assert speed == pytest.approx(TNT["D"], rel=0.02)
    assert r[-1, 2] == pytest.approx(TNT["P_CJ"], rel=0.05)
    assert np.all(np.diff(r[:, 2]) > 0)  # approaching it from below
    # behind the front everything burned; ahead only the beta burn's trace of
    # the compression the kernel reaches 5 mm ahead (< 1e-3)
    x_front = r[-1, 1]
    burned = p.hist[:, H_BURN]
    assert np.all(burned[p.x[:, 0] < x_front - 0.005] == 1.0)
    assert np.all(burned[p.x[:, 0] > x_front + 0.005] < 1e-3)


def _lighting_volumes(burn: str, t_end: float = 8e-6):
    """A 1D TNT column of 1600 particles in 0.1 m run to ``t_end``: each
    particle's relative volume at its lighting time (NaN if not yet lit) and
    the peak pressure now [Pa]."""
    st, part = tnt_slab(n=1600, burn=burn)
    p = part.p
    lit_at = p.x[:, 0] / TNT["D"]
    v_lit = np.full(p.n, np.nan)
    while st.t < t_end:
        st.step(t_stop=t_end)
        now = np.isnan(v_lit) & (st.t >= lit_at)
        v_lit[now] = p.rho0[now] / p.rho[now]
    return p.x[:, 0], v_lit, float(np.max(-p.sig[:, 0, 0]))


def test_a_long_front_stays_at_cj_with_both_and_overdrives_programmed_alone():
    # docs/theory.md "Fluids": with the programmed burn alone the burned
    # particles compress the unlit ones through the kernel before their
    # lighting time, so they burn at a smaller relative volume and a higher
    # pressure, and this grows (measured V at lighting 0.89 at 25 mm, 0.62
    # at 55 mm; peak 49 GPa at 8 us); with the beta part (both, the default)
    # a compressed particle burns at once: V at lighting stays above 0.8
    # (measured 0.835 at the front) and the peak near P_CJ (21.7 GPa: 5 %)
    x, v_lit, peak = _lighting_volumes("both")
    assert np.nanmin(v_lit) > 0.8
    assert peak == pytest.approx(TNT["P_CJ"], rel=0.05)
    x, v_lit, peak = _lighting_volumes("programmed")
    assert np.nanmin(v_lit[x > 0.05]) < 0.75 and peak > 1.5 * TNT["P_CJ"]
    assert np.nanmin(v_lit[x < 0.025]) > 0.85  # early on it is not yet compressed


def test_chemical_energy_released_and_the_balance_closes():
    # E_chemical = burned mass x E0/rho0 (to round-off); the balance E_kin +
    # E_int - E_chemical stays 0 within 0.5 % of E_chemical (measured 0.33 %
    # at cfl 0.3: a first-order error of the leapfrog at the burn front,
    # which halves with the step, checked here too)
    drifts = []
    for cfl in (0.3, 0.15):
        st, part = tnt_slab(n=200, cfl=cfl)
        while st.t < 6e-6:
            st.step(t_stop=6e-6)
        p = part.p
        rec = st.record()
        burned = float(np.dot(p.m, p.hist[:, H_BURN]))
        assert rec["E_chemical"] == pytest.approx(burned * TNT["E0"] / TNT["density"],
                                                  rel=1e-12)
        assert 0.3 < burned / p.m.sum() < 0.5  # the front is 42 mm into 100 mm
        drifts.append(rec["E_total"] / rec["E_chemical"])
    assert abs(drifts[0]) < 5e-3
    assert drifts[1] / drifts[0] == pytest.approx(0.5, abs=0.1)


def sod(n_left=400, correction=True):
    """Sod's shock tube (rho, p = 1, 1 | 0.125, 0.1; gamma 1.4) of equal-mass
    particles on [-1, 1], three fixed at each end."""
    gas = get_model("gas")
    dx_l = 1.0 / n_left
    x_l = np.arange(-1.0 + 0.5 * dx_l, 0.0, dx_l)
    x_r = np.arange(0.5 * 8 * dx_l, 1.0, 8 * dx_l)
    x = np.concatenate([x_l, x_r])
    left = x < 0
    p = _particles(x, np.where(left, dx_l, 8 * dx_l), np.where(left, 1.0, 0.125), 1)
    p.mat[:] = np.where(left, 0, 1)
    p.bc[:3] = BC_FIXED
    p.bc[-3:] = BC_FIXED
    groups = []
    for k, (rho, pr) in enumerate(((1.0, 1.0), (0.125, 0.1))):
        prm = gas.pack({"density": rho, "pressure": pr})
        g = MaterialGroup(str(k), gas, prm, np.flatnonzero(p.mat == k).astype(np.int64), k)
        e0, p0 = gas.initial_state(prm)
        p.e[g.idx] = e0
        p.sig[g.idx] = -p0 * np.eye(3)
        p.c[g.idx] = gas.wave_speed(prm, rho)
        groups.append(g)
    part = SPHPart(p, groups, KernelContext.named("cubic_spline", 1, 1.0),
                   _settings(correction, ((1e-3, 20.0),) * 2))
    st = Stepper([part])
    while st.t < 0.2:
        st.step(t_stop=0.2)
    return st, part


@pytest.mark.parametrize("correction,bound", [(True, 0.008), (False, 0.016)])
def test_sod_shock_tube_against_the_exact_solution(correction, bound):
    # 400 particles per unit length on the left, 50 on the right (equal
    # masses), t = 0.2: L1 error of the density over [-0.5, 0.5] below the
    # bound (measured 0.0060 with the gradient correction, 0.0137 without;
    # it falls with resolution: 0.019, 0.014, 0.010 at 200, 400, 800), the
    # shock (half way up its density jump) within 2 % of 0.2 times its speed
    # (measured 0.5 % and 0.8 % ahead); energy conserved to 1e-3
    left, right = (1.0, 0.0, 1.0), (0.125, 0.0, 0.1)
    st, part = sod(correction=correction)
    p = part.p
    o = np.argsort(p.x[:, 0])
    x, rho = p.x[o, 0], p.rho[o]
    sel = (x > -0.5) & (x < 0.5)
    exact = sample(x[sel], 0.2, left, right, 1.4)[0]
    assert np.trapezoid(np.abs(rho[sel] - exact), x[sel]) < bound
    rho_star = sample(np.array([0.3]), 0.2, left, right, 1.4)[0, 0]  # behind the shock
    mid = 0.5 * (rho_star + right[0])
    k = int(np.flatnonzero((x > 0.25) & (rho > mid)).max())
    x_shock = x[k] + (x[k + 1] - x[k]) * (rho[k] - mid) / (rho[k] - rho[k + 1])
    assert x_shock == pytest.approx(0.2 * shock_speed(left, right, 1.4), rel=0.02)
    rec = st.record()
    assert rec["E_total"] == pytest.approx(2.75, rel=1e-3)  # 1/0.4 + 0.1/0.4


# ------------------------------------------------------------------ deck
def _deck(dim=2, material=None, detonation=None, extra=None):
    d = {
        "run": {"title": "he", "dimension": dim, "t_end": 2e-6},
        "material": [material or {"name": "tnt", "model": "high_explosive",
                                  "preset": "tnt"},
                     {"name": "air", "model": "gas", "density": 1.225,
                      "pressure": 101325.0}],
        "body": [{"name": "charge", "material": "tnt", "dx": 1e-3,
                  "geometry": {"shape": "box", "lo": [0, 0], "hi": [0.01, 0.01]}}],
        "detonation": [{"point": [0.0005, 0.005]}] if detonation is None else detonation,
    }
    d.update(extra or {})
    return d


def load_deck_dict(d):
    """Validate a deck given as a dict, through its TOML text (as a file)."""
    return loads_deck(tomli_w.dumps(d))


def _problems(d):
    with pytest.raises(DeckError) as exc:
        load_deck_dict(d)
    return str(exc.value)


def test_deck_preset_overrides_and_defaults():
    deck = load_deck_dict(_deck(material={"name": "tnt", "model": "high_explosive",
                                          "preset": "tnt", "D": "6.9 km/s"}))
    m = deck.material[0]
    assert (m.density, m.D, m.A, m.E0, m.burn) == (1630.0, 6900.0, 371.2e9, 7.0e9, "both")
    assert m.min_density_factor == 1e-3


@pytest.mark.parametrize("material,needle", [
    ({"name": "tnt", "model": "high_explosive", "density": 1630.0}, "has no D"),
    ({"name": "tnt", "model": "high_explosive", "preset": "tnt", "A": -1e9},
     "material[0].A: -1000000000.0 is out of range"),
    ({"name": "tnt", "model": "high_explosive", "preset": "tnt", "P_CJ": 1e11},
     "P_CJ = 1e+11 Pa is not below rho0 D^2"),
    ({"name": "tnt", "model": "high_explosive", "preset": "tnt", "R1": 0},
     "material[0].R1: 0.0 is out of range"),
])
def test_deck_rejects_bad_explosives(material, needle):
    assert needle in _problems(_deck(material=material))


def test_deck_rejects_a_burn_without_detonation_and_a_detonation_of_no_explosive():
    assert "no [[detonation]] lights it" in _problems(_deck(detonation=[]))
    d = _deck(detonation=[{"point": [0, 0], "material": "air"}])
    assert "detonation[0].material 'air' is not a high explosive" in _problems(d)
    # beta burn needs no point
    load_deck_dict(_deck(material={"name": "tnt", "model": "high_explosive",
                                   "preset": "tnt", "burn": "beta"}, detonation=[]))


def test_gas_eos_keys_are_checked():
    gas = {"name": "air", "model": "gas", "density": 1.2, "C1": 1e5}
    d = _deck()
    d["material"][1] = gas
    assert "linear polynomial" in _problems(d)
    d["material"][1] = {**gas, "C1": None, "eos": "linear_polynomial", "gamma": 1.4}
    del d["material"][1]["C1"]
    assert "gamma belongs to the ideal gas" in _problems(d)
    d["material"][1] = {"name": "air", "model": "gas", "density": 1.2, "pressure": 1e5,
                        "E0": 2.5e5}
    assert "both pressure and E0" in _problems(d)


def test_detonation_point_outside_the_charge_is_refused_naming_the_field():
    from sphdyn.build.model import build_model
    deck = load_deck_dict(_deck(detonation=[{"point": [0.05, 0.005]}]))
    with pytest.raises(DeckError, match=r"detonation\[0\]\.point"):
        build_model(deck)


def test_deck_run_lights_the_charge_and_books_the_chemical_energy():
    # a 2D charge lit at its left edge, 40 steps: lighting times from the
    # point, particles burning from the left, the history's E_chemical and
    # a closed energy balance (within 2 % of E_chemical so early: the
    # first-order front error of test_chemical_energy_released...)
    from sphdyn.build import build_stepper
    from sphdyn.build.model import build_model
    deck = load_deck_dict(_deck())
    model = build_model(deck)
    p = model.particles
    col = p.hist_names.index("burn_clock")
    dist = np.linalg.norm(p.x - np.array([0.0005, 0.005, 0.0]), axis=1)
    assert np.allclose(-p.hist[:, col], dist / 6930.0, rtol=1e-14, atol=0.0)
    st = build_stepper(deck, model)
    for _ in range(15):
        st.step()
    rec = st.record()
    assert rec["E_chemical"] > 0.0
    assert abs(rec["E_total"]) < 0.02 * rec["E_chemical"]
    burn = p.hist[:, p.hist_names.index("burn_fraction")]
    reach = 6930.0 * st.t  # the front's distance from the point
    assert np.all(burn[dist < reach - 2e-3] == 1.0)
    assert np.all(burn[dist > reach + 2e-3] < 0.5)
    assert 0 < np.count_nonzero(dist > reach + 2e-3) < p.n


def test_material_viscosity_and_time_step_factor_reach_the_particles():
    from sphdyn.build import build_stepper
    d = _deck(extra={"sph": {"viscosity": {"alpha": 0.5, "beta": 1.0}}})
    d["material"][0]["viscosity"] = {"beta": 3.0}
    d["material"][0]["time_step_factor"] = 0.5
    st = build_stepper(load_deck_dict(d))
    p = st.parts[0].p
    assert np.all(p.av_alpha == 0.5) and np.all(p.av_beta == 3.0)
    assert np.all(p.dt_factor == 0.5) and np.all(p.dt_viscous == 1.2)


def test_restart_of_a_burning_charge_is_bitwise():
    # checkpoint after 6 steps of the 2D deck (the front and its viscous
    # signal speed, which sets the fluids' step, mid-charge), restore into a
    # fresh model, 6 more steps: every particle array and the books equal
    from stepping import restarted_pair

    def advance(st):
        for _ in range(6):
            st.step()

    st, st2 = restarted_pair(load_deck_dict(_deck()), advance, 6)
    for name, arr in st.parts[0].p.arrays().items():
        assert np.array_equal(arr, getattr(st2.parts[0].p, name)), name
    assert st.record() == st2.record()


def _examples_module():
    import importlib.util
    path = Path(__file__).resolve().parents[1] / "examples" / "explosives_1d.py"
    spec = importlib.util.spec_from_file_location("explosives_1d", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_gurney_formula_is_written_out():
    ex = _examples_module()
    # M/C = 1: [(27 + 1)/12 + 1]^(-1/2) sqrt(2E)
    assert ex.gurney_open_face(1.0, 1.0) == pytest.approx((28 / 12 + 1) ** -0.5, rel=1e-14)
    assert ex.gurney_open_face(0.0, 1.0) == pytest.approx(math.sqrt(3.0), rel=1e-14)


def test_gurney_plate_from_the_example_deck(tmp_path):
    # examples/gurney_1d.toml (1D, 0.1 mm particles, 10 mm TNT lit at its free
    # face, 2.076 mm steel, M/C = 1): the plate's mean velocity at 30 us
    # within 10 % of Gurney's 1336 m/s (measured 1372 m/s, +2.6 %) and nearly
    # terminal (less than 1 % gained over the last 5 us; measured 0.6 %);
    # the energy balance within 1 % of the chemical energy (measured 0.56 %)
    from sphdyn.io import read_history_csv
    from sphdyn.simulation import run_deck
    ex = _examples_module()
    run_deck(Path(ex.ROOT) / "examples" / "gurney_1d.toml", tmp_path,
             overrides=["output.vtk=false", "output.progress=false"])
    g = ex.gurney_result(tmp_path)
    assert g["v"][-1] == pytest.approx(g["gurney"], rel=0.10)
    late = g["t"] >= g["t"][-1] - 5e-6
    assert g["v"][-1] / g["v"][late][0] < 1.01
    h = read_history_csv(tmp_path / "history.csv")
    assert np.max(np.abs(h["E_total"])) < 0.01 * h["E_chemical"][-1]


def test_sod_shock_tube_example_deck(tmp_path):
    # examples/sod_shock_tube.toml against the exact solution, as the
    # programmatic run above (its bounds: L1 < 0.008, shock within 2 %)
    from sphdyn.simulation import run_deck
    ex = _examples_module()
    run_deck(Path(ex.ROOT) / "examples" / "sod_shock_tube.toml", tmp_path,
             overrides=["output.vtk=false", "output.progress=false"])
    sod = ex.sod_result(tmp_path)
    assert sod["l1"] < 0.008
    assert sod["x_shock"] == pytest.approx(sod["x_shock_exact"], rel=0.02)


def _expanding_gas_deck(outside="remove"):
    """1D: a gas slab at 1 bar expanding into vacuum, the domain 2 cm beyond
    each face."""
    return {"run": {"dimension": 1, "t_end": 2e-4},
            "sph": {"correction": True, "smoothing_length": {
                "mode": "benz", "min_factor": 0.1, "max_factor": 20.0}},
            "domain": {"lo": [-0.02], "hi": [0.12], "outside": outside},
            "material": [{"name": "air", "model": "gas", "density": 1.2,
                          "pressure": 1e5}],
            "body": [{"name": "slab", "material": "air", "dx": 1e-3,
                      "geometry": {"shape": "box", "lo": [0], "hi": [0.1]}}]}


def test_the_domain_check_counts_and_lists_the_rows_outside():
    """The every-step check of [domain] outside = "remove": count_outside
    counts, and outside_rows lists in order, exactly the active
    updated-Lagrangian rows outside the box (against a NumPy mask), on any
    side and on none."""
    from sphdyn.events.domain_exit import count_outside, outside_rows

    rng = np.random.default_rng(3)
    x = rng.uniform(-1.5, 1.5, (5000, 3))
    active = (rng.uniform(size=5000) > 0.1).astype(np.int8)
    tl = rng.uniform(size=5000) < 0.1
    lo, hi = np.full(3, -1.0), np.full(3, 1.0)
    want = np.flatnonzero((active != 0) & ~tl & np.any((x < lo) | (x > hi), axis=1))
    n = count_outside(x, active, tl, lo, hi)
    assert n == want.size > 0
    assert np.array_equal(outside_rows(x, active, tl, lo, hi, n), want)
    assert count_outside(x, active, tl, lo - 2.0, hi + 2.0) == 0


def test_particles_leaving_the_domain_are_removed_and_booked():
    # the free faces' particles fly off at several hundred m/s and leave the
    # 2 cm margin within 0.1 ms: removed (fixed, out of the lists, active 0),
    # the rest runs on; E_total (with E_left_domain) stays within 1e-3 of the
    # initial energy (the benz 1D gas alone drifts ~1e-4)
    import copy

    from sphdyn.build import build_stepper
    deck = load_deck_dict(_expanding_gas_deck())
    st = build_stepper(deck)
    e0 = st.record()["E_total"]
    scalars = groups = None
    builds0, removals, removed = st.parts[0].nl.n_builds, 0, 0
    while st.t < 2e-4:
        st.step()
        if st.record()["particles_removed"] > removed:
            removals += 1
            removed = st.record()["particles_removed"]
        if scalars is None and st.record()["particles_removed"] > 0:
            scalars, groups = copy.deepcopy(st.state())  # after the first removals
            at = st.step_count
    rec = st.record()
    # each removal rebuilds the list in place and is counted (the run's
    # summary reports the builds: a new list at each removal restarted the count)
    assert removals > 1 and st.parts[0].nl.n_builds >= builds0 + removals
    p = st.parts[0].p
    gone = p.active == 0
    assert 0 < rec["particles_removed"] == gone.sum() < p.n
    assert np.all(p.v[gone] == 0.0) and np.all(p.e[gone] == 0.0)
    nl = st.parts[0].nl
    rows = np.repeat(np.arange(p.n), np.diff(nl.offsets))
    assert not np.any(gone[rows]) and not np.any(gone[nl.idx])  # out of the lists
    assert rec["E_left_domain"] > 0.0
    assert rec["E_total"] == pytest.approx(e0, rel=1e-3)
    # a restart from a state with particles removed continues bit for bit
    assert at < st.step_count - 10
    st2 = build_stepper(deck)
    st2.restore(scalars, groups)
    while st2.step_count < st.step_count:
        st2.step()
    for name, arr in p.arrays().items():
        assert np.array_equal(arr, getattr(st2.parts[0].p, name)), name
    assert st2.record() == st.record()


def test_particles_leaving_the_domain_stop_the_run_by_default():
    from sphdyn.build import build_stepper
    from sphdyn.watchers.guards import SimulationFailed, check_particles
    st = build_stepper(load_deck_dict(_expanding_gas_deck("stop")))
    p = st.parts[0].p
    with pytest.raises(SimulationFailed, match="left the domain box"):
        while st.t < 2e-4:
            st.step()
            check_particles(p, np.array([-0.02, -np.inf, -np.inf]),
                            np.array([0.12, np.inf, np.inf]), st.t, st.step_count,
                            np.zeros(p.n, np.int8))


def test_blast_slab_coarse_first_100_us(tmp_path):
    # examples/blast_slab_coarse.toml for 100 us (about 800 steps): the whole
    # charge burns (E_chemical = its mass x E0/rho0 to round-off) within
    # 12 us (70 mm at D), the products load the slab (its particles move,
    # its bottom centre goes down), products leave the box and are removed,
    # and the energy balance holds within 3 % of the released energy
    # (measured 1.9 %: the 3D front error, docs/theory.md)
    from sphdyn.deck import load_deck
    from sphdyn.io import read_history_csv
    from sphdyn.simulation import Simulation
    deck = load_deck(Path(__file__).resolve().parents[1] / "examples" /
                     "blast_slab_coarse.toml",
                     ["run.t_end=1e-4", "output.vtk=false", "output.progress=false",
                      "output.history_every=5", "output.checkpoint_every=0"])
    sim = Simulation.from_deck(deck, tmp_path)
    sim.run()
    p = sim.particles
    charge = p.mat == 3
    h = read_history_csv(tmp_path / "history.csv")
    q = TNT["E0"] / TNT["density"]
    assert h["E_chemical"][-1] == pytest.approx(p.m[charge].sum() * q, rel=1e-9)
    burned_at = h["time"][np.argmax(h["E_chemical"] >= 0.999999 * h["E_chemical"][-1])]
    assert burned_at < 12e-6
    slab = p.body == 0
    assert np.abs(p.v[slab, 2]).max() > 1.0
    assert h["particles_removed"][-1] > 0
    assert np.max(np.abs(h["E_total"])) < 0.03 * h["E_chemical"][-1]
    disp = read_history_csv(tmp_path / "gauges" / "bottom_centre.csv")
    assert disp["displacement_z"][-1] < -1e-5


def test_a_detonation_point_turns_with_its_tilted_charge():
    # the charge tilted 90 degrees about y: the point given at the upright
    # charge's top centre lights the (now sideways) end first
    from sphdyn.build.model import build_model
    d = _deck(dim=3, material=None, detonation=[{"point": [0.005, 0.005, 0.0115],
                                                 "rotate_with": "charge"}])
    d["body"][0]["geometry"] = {"shape": "cylinder", "centre": [0.005, 0.005, 0.0],
                                "radius": 0.003, "length": 0.024, "axis": "z",
                                "tilt": 90.0}
    model = build_model(load_deck_dict(d))
    p = model.particles
    t_l = -p.hist[p.mat == 0, p.hist_names.index("burn_clock")]
    x = p.x[p.mat == 0]
    assert np.ptp(x[:, 0]) > 0.02 > np.ptp(x[:, 2])  # lying along x
    assert x[np.argmin(t_l), 0] > 0.005 + 0.01  # lit at the end at +x
    point = np.array([0.005 + 0.0115, 0.005, 0.0])
    assert np.allclose(t_l, np.linalg.norm(x - point, axis=1) / 6930.0, rtol=1e-12)
    # without rotate_with the same point lies outside the turned charge
    d["detonation"][0].pop("rotate_with")
    with pytest.raises(DeckError, match=r"detonation\[0\]\.point"):
        build_model(load_deck_dict(d))


def test_tilt_is_refused_outside_3d():
    d = _deck()
    d["body"][0]["geometry"] = {"shape": "cylinder", "centre": [0.005, 0.005],
                                "radius": 0.004, "tilt": 30.0}
    assert "tilt turns a cylinder in 3D only" in _problems(d)


@pytest.mark.parametrize("plate_mm", [1.0, 4.2])
def test_gurney_over_the_mass_ratio(tmp_path, plate_mm):
    # the deck with lighter and heavier plates (10 and 42 particles of 0.1 mm:
    # M/C = 0.48 and 2.02): the plate at 30 us within 10 % of Gurney's
    # velocity for its M/C (measured +7.2 % and +1.1 %; the light plate is
    # still gaining, Gurney's linear velocity profile fits heavy plates best)
    from sphdyn.simulation import run_deck
    ex = _examples_module()
    run_deck(Path(ex.ROOT) / "examples" / "gurney_1d.toml", tmp_path,
             [f'body.plate.geometry.hi=["{10.0 + plate_mm} mm"]', "output.vtk=false",
              "output.progress=false"])
    g = ex.gurney_result(tmp_path)
    m_over_c = round(plate_mm / 0.1) * 7850.0 / (100 * 1630.0)
    assert g["v"][-1] == pytest.approx(ex.gurney_open_face(m_over_c), rel=0.10)
