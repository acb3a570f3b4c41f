"""Whole-run verification against analytical results and conservation laws.

Every case is a small deck run through the same code path as ``sphdyn run``.
"""

import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.build.model import build_model
from stepping import build_stepper, step, wall

ELASTIC = """
[[material]]
name = "m"
model = "elastic"
density = {rho}
E = {E}
nu = {nu}
"""


def _solver(text):
    deck = loads_deck(text)
    return build_stepper(deck), deck


def _run_until(solver, t_end, probe=None):
    out = []
    while solver.t < t_end:
        solver.step()
        if probe is not None:
            out.append((solver.t, probe(solver)))
    return out


# ----------------------------------------------------------------- wave speed
def _column_deck(dim, dx, length, width, v0=1.0):
    zhi = width if dim == 3 else 0.0
    return f"""
[run]
dimension = {dim}
t_end = 1.0
[sph.viscosity]
alpha = 0.5
beta = 0.0
[domain]
margin = 0.5
{ELASTIC.format(rho=2400.0, E=30e9, nu=0.25)}
[[body]]
name = "col"
material = "m"
dx = {dx}
geometry = {{ shape = "box", lo = [0, 0, 0], hi = [{length}, {width}, {zhi}] }}
[[set]]
name = "piston"
region = {{ shape = "box", lo = [-1, -1, -1], hi = [{1.01 * dx}, 1, 1] }}
[[boundary]]
set = "piston"
type = "velocity"
velocity = [{v0}, 0, 0]
"""


def _front_arrival(solver, deck_dx, positions, v0, t_end):
    """Times at which the particle velocity on the centre line reaches v0/2."""
    p = solver.part("sph").kin
    x0 = p.x0
    yc = 0.5 * (x0[:, 1].min() + x0[:, 1].max())
    zc = 0.5 * (x0[:, 2].min() + x0[:, 2].max())
    probes = [np.argmin((x0[:, 0] - xp) ** 2 + (x0[:, 1] - yc) ** 2 + (x0[:, 2] - zc) ** 2)
              for xp in positions]
    hist = _run_until(solver, t_end, lambda s: s.part("sph").kin.v[probes, 0].copy())
    t = np.array([h[0] for h in hist])
    v = np.array([h[1] for h in hist])
    arrivals = []
    for k in range(len(probes)):
        i = np.flatnonzero(v[:, k] >= 0.5 * v0)[0]
        # linear interpolation of the half-amplitude crossing
        f = (0.5 * v0 - v[i - 1, k]) / (v[i, k] - v[i - 1, k])
        arrivals.append(t[i - 1] + f * (t[i] - t[i - 1]))
    return np.array([x0[k, 0] for k in probes]), np.array(arrivals)


def _wave_speed(dim, dx, width, sph_options):
    text = _column_deck(dim, dx, 0.2, width).replace(
        "[sph.viscosity]", "[sph]\n" + sph_options + "\n[sph.viscosity]")
    s, _ = _solver(text)
    xs, ts = _front_arrival(s, dx, [0.04, 0.1], 1.0, 0.11 / CP)
    return (xs[1] - xs[0]) / (ts[1] - ts[0])


E_COL, NU_COL, RHO_COL = 30e9, 0.25, 2400.0
_K = E_COL / (3 * (1 - 2 * NU_COL))
_G = E_COL / (2 * (1 + NU_COL))
CP = np.sqrt((_K + 4 * _G / 3) / RHO_COL)


@pytest.mark.parametrize("sph_options", ["h_factor = 1.5", "correction = true"])
def test_p_wave_speed_in_laterally_confined_column(sph_options):
    # A piston drives a step wave into a wide plane-strain block; on the
    # centre line the material is in uniaxial strain (laterally confined), so
    # the front (half amplitude) travels at c_P = sqrt((K + 4G/3)/rho).
    # Tolerance 2 % (issue). Measured: 0.2 % with h = 1.5 dx, 0.6 % with the
    # Randles-Libersky correction. (Uncorrected SPH with h = 1.2 dx is about
    # 2 % slow in 2D and 3 % in 3D: the lattice sum of the kernel gradient
    # misses I by 1-2 %, which softens the discrete operator; docs/theory.md.)
    c = _wave_speed(2, 2e-3, 0.2, sph_options)
    assert abs(c / CP - 1) < 0.02, (c, CP)


@pytest.mark.slow
def test_2d_and_3d_agree_on_plane_strain_wave():
    # The same confined-column problem in 3D (wide in y and z: uniaxial
    # strain on the centre line, the plane-strain state of the 2D model)
    # gives the 2D wave speed: both within 2 % of c_P and of each other
    # (measured 0.6 % and 1.0 % from c_P, 0.4 % apart).
    c2 = _wave_speed(2, 5e-3, 0.2, "correction = true")
    c3 = _wave_speed(3, 5e-3, 0.2, "correction = true")
    assert abs(c2 / CP - 1) < 0.02 and abs(c3 / CP - 1) < 0.02, (c2, c3, CP)
    assert abs(c3 / c2 - 1) < 0.02, (c2, c3)


# -------------------------------------------------------- bounce off the wall
def _disc_on_wall(stiffness="mass", alpha=0.1, vel=5.0, friction=0.0, vx=0.0):
    return f"""
[run]
dimension = 2
t_end = 1.0
[sph.viscosity]
alpha = 0.3
beta = 0.0
[domain]
margin = 10.0
{ELASTIC.format(rho=1000.0, E=1e7, nu=0.3)}
[[body]]
name = "disc"
material = "m"
dx = 1e-3
velocity = [{vx}, {-vel}, 0]
geometry = {{ shape = "cylinder", centre = [0, 0.0106, 0], radius = 0.01 }}
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
stiffness = "{stiffness}"
alpha = {alpha}
friction = {friction}
"""


@pytest.mark.parametrize("stiffness,alpha", [("mass", 0.1), ("bulk", 0.5)])
def test_elastic_disc_bounces_with_energy_conserved(stiffness, alpha):
    # Total energy (kinetic + internal incl. viscous heat + contact) is
    # conserved by the scheme to O(dt^2); tolerance 2 % of the initial kinetic
    # energy over the whole impact. The rebound speed of the centre of mass
    # is at least 80 % of the impact speed (energy lost to elastic vibration
    # of the disc and to artificial viscosity only) and at most 100.5 %.
    # Measured: drift 0.55 % (mass) / 0.39 % (bulk), rebound 95 % / 96 %.
    s, _ = _solver(_disc_on_wall(stiffness, alpha))
    m = s.part("sph").kin.m
    vel0 = 5.0
    records = []
    t_end = 0.003  # contact lasts from 0.12 to 0.76 ms
    while s.t < t_end:
        records.append(step(s))
    e = np.array([r["E_total"] for r in records])
    ke0 = records[0]["E_kinetic"]
    assert np.abs(e - e[0]).max() < 0.02 * ke0
    vcm = (m[:, None] * s.part("sph").kin.v).sum(axis=0) / m.sum()
    assert vcm[1] > 0.8 * vel0 and vcm[1] < 1.005 * vel0, vcm
    assert max(r["F_wall_floor"] for r in records) > 0
    assert records[-1]["contacts_floor"] == 0  # it has left the wall


def test_bulk_wall_with_random_masses_keeps_the_time_step_and_energy():
    # Paper eq. 9 with a uniform [0, 2] mass field: the bulk spring acts on
    # the nominal inertia rho0 V, so the contact time step equals the
    # homogeneous one (instead of collapsing with the lightest particle) and
    # the bounce still closes the energy balance within 2 % of the impact
    # energy (the tolerance of the homogeneous test above; measured 1.3 %,
    # rebound 0.79 of the impact speed).
    hom, _ = _solver(_disc_on_wall("bulk", 0.5))
    text = _disc_on_wall("bulk", 0.5).replace(
        "[[wall]]", '[body.mass]\ndistribution = "uniform"\nlow = 0.0\nhigh = 2.0\n[[wall]]')
    s, _ = _solver(text)
    assert s.part("sph").kin.m.min() < 0.01 * s.part("sph").kin.m.mean()  # some very light particles
    assert wall(s, "floor").stable_dt() == wall(hom, "floor").stable_dt()
    records = []
    while s.t < 0.003:
        records.append(step(s))
    e = np.array([r["E_total"] for r in records])
    assert np.abs(e - e[0]).max() < 0.02 * records[0]["E_kinetic"]
    vcm = (s.part("sph").kin.m[:, None] * s.part("sph").kin.v).sum(axis=0) / s.part("sph").kin.m.sum()
    assert vcm[1] > 0.5 * 5.0  # bounced


def test_friction_slows_sliding_but_not_without_it():
    # Oblique impact: Coulomb friction removes tangential momentum, frictionless
    # contact keeps it (to round-off: normal forces have no x component).
    vt = []
    for mu in (0.0, 0.5):
        s, _ = _solver(_disc_on_wall(friction=mu, vx=3.0))
        while s.t < 0.006:
            s.step()
        vt.append((s.part("sph").kin.m * s.part("sph").kin.v[:, 0]).sum() / s.part("sph").kin.m.sum())
    assert abs(vt[0] - 3.0) < 1e-9
    assert vt[1] < 2.9


@pytest.mark.parametrize("stiffness,alpha,mu", [("mass", 0.1, 0.5), ("bulk", 0.5, 0.0)])
def test_wall_impulse_equals_the_momentum_change(stiffness, alpha, mu):
    # Newton's second law for the whole body: the internal SPH forces cancel
    # pairwise, so the momentum change equals the impulse the wall has given,
    # which the solver sums as F^n dt_kick over the kicks. Both are the same
    # floating-point sums in a different order: equal to 1e-9 of the impact
    # momentum (round-off over ~700 steps; measured 5e-15 and 7e-15). Oblique
    # impact with friction, so the tangential component is checked too.
    s, _ = _solver(_disc_on_wall(stiffness, alpha, friction=mu, vx=2.0))
    p0 = (s.part("sph").kin.m[:, None] * s.part("sph").kin.v).sum(axis=0)
    records = []
    while s.t < 0.002:
        records.append(step(s))
    dp = (s.part("sph").kin.m[:, None] * s.part("sph").kin.v).sum(axis=0) - p0
    scale = np.linalg.norm(p0)
    assert np.abs(dp - wall(s, "floor").impulse).max() < 1e-9 * scale
    assert dp[1] > 1.5 * abs(p0[1])  # it bounced: the impulse is no trivial 0
    if mu > 0:
        assert dp[0] < -0.01 * p0[0]  # friction took tangential momentum
    # the history column is the normal component, running with the steps
    imp = np.array([r["I_wall_floor"] for r in records])
    assert np.all(np.diff(imp) >= 0)  # a wall can only push
    assert abs(imp[-1] - wall(s, "floor").impulse[1]) <= abs(records[-1]["F_wall_floor"]) * \
        records[-1]["dt"] + 1e-12 * scale


def test_a_step_shortened_to_end_the_run_keeps_the_wall_spring_stiffness():
    # The last step of a run is shortened to land on t_end. The mass-based
    # spring k = alpha m / dt^2 (paper eq. 8) must use the stable step, or a
    # step 100x shorter makes the wall force 1e4x larger (a false peak in
    # every history and summary that ended in contact, and a huge kick after
    # a restart). One step moves the penetrations by v dt only, so the force
    # after the short step stays within 10 % of the force before it.
    s, _ = _solver(_disc_on_wall("mass", 0.1))
    while s.t < 0.4e-3:  # mid-contact (contact from 0.12 to 0.76 ms)
        s.step()
    before = wall(s, "floor").total[1]
    assert before > 0
    dt = s.stable_dt()[0]
    s.step(t_stop=s.t + 0.01 * dt)
    after = wall(s, "floor").total[1]
    assert abs(after - before) < 0.1 * before, (before, after)


def test_window_mean_force_of_a_spring_oscillation_is_its_mean():
    # F(t) = F0 (1 + sin(2 pi t / T)): I(t) = F0 t + F0 T (1 - cos(2 pi t/T)) / (2 pi).
    # Over a window of one period the mean is exactly F0 (records on a grid
    # that divides T, so the interpolation of I is exact: 1e-12 relative);
    # before a full window has passed, the impulse before t = 0 counts as 0,
    # so the mean is I(t) / T.
    from sphdyn.analysis.fragments import window_mean_force
    F0, T = 3.0e4, 4.0e-6
    t = np.arange(0, 201) * (T / 40)
    imp = F0 * t + F0 * T * (1 - np.cos(2 * np.pi * t / T)) / (2 * np.pi)
    mean = window_mean_force(t, imp, T)
    assert np.allclose(mean[t >= T], F0, rtol=1e-12, atol=0)
    assert np.allclose(mean[t < T], imp[t < T] / T, rtol=1e-12, atol=0)
    # the raw signal peaks at 2 F0; the mean over half a period peaks at
    # F0 (1 + 2/pi) (the integral of sin over half its period is 2/pi of it)
    half = window_mean_force(t, imp, T / 2)
    assert np.isclose(half.max(), F0 * (1 + 2 / np.pi), rtol=1e-12, atol=0)
    with pytest.raises(ValueError, match="window"):
        window_mean_force(t, imp, 0.0)


# ------------------------------------------------------------ moving walls
def test_moving_wall_unit_behaviour():
    # A particle at rest, 3 mm above a wall moving up at 1 m/s, is touched
    # when the plane is within thickness_factor * size = 0.5 mm, i.e. at
    # t = 2.5 ms; friction acts on the velocity relative to the wall, so a
    # particle sliding with the wall's tangential velocity feels none.
    from sphdyn.interactions.wall_contact import STIFFNESS_MASS, wall_contact
    x = np.array([[0.0, 3e-3, 0.0]])
    one = np.ones(1)
    args = (one, np.full(1, 1e-6), one, one, 2)
    n = np.array([0.0, 1.0, 0.0])
    u = np.array([0.0, 1.0, 0.0])
    for t, touching in ((2.49e-3, 0), (2.51e-3, 1)):
        a, f = np.zeros((1, 3)), np.zeros((1, 3))
        cnt = wall_contact(x, np.zeros((1, 3)), *args, u * t, n, u, 0.5, STIFFNESS_MASS,
                           0.1, 0.0, 1e-6, a, f, np.zeros(1), np.zeros(1))
        assert cnt == touching and (a[0, 1] > 0) == bool(touching)
    belt = np.array([2.0, 0.0, 0.0])  # a wall sliding along x at 2 m/s
    for v, expect_friction in (([2.0, 0.0, 0.0], False), ([0.0, 0.0, 0.0], True)):
        a, f = np.zeros((1, 3)), np.zeros((1, 3))
        wall_contact(np.array([[0.0, 0.2e-3, 0.0]]), np.array([v]), *args,
                     np.zeros(3), n, belt, 0.5, STIFFNESS_MASS, 0.1, 0.5, 1e-6, a, f,
                     np.zeros(1), np.zeros(1))
        assert (a[0, 0] != 0.0) == expect_friction
        if expect_friction:
            assert a[0, 0] > 0.0  # dragged along by the wall


def test_wall_velocity_ramp():
    # ramp_time T: v(t) = u t/T, displacement u t^2/(2T) up to T, then
    # u (t - T/2); continuous in position and velocity at T.
    from sphdyn.interactions import WallSpec
    w = WallSpec("w", np.zeros(3), np.array([0.0, -1.0, 0.0]), 0, 1.0, 0.0, 0.5,
                 velocity=np.array([0.0, -2.0, 0.0]), ramp_time=1e-3)
    assert w.point_at(0.5e-3)[1] == pytest.approx(-2.0 * 0.25e-6 / 2e-3, rel=1e-12)
    assert w.velocity_at(0.5e-3)[1] == pytest.approx(-1.0, rel=1e-12)
    eps = 1e-12
    assert w.point_at(1e-3 - eps)[1] == pytest.approx(w.point_at(1e-3 + eps)[1], rel=1e-6)
    assert w.point_at(3e-3)[1] == pytest.approx(-2.0 * 2.5e-3, rel=1e-12)
    assert w.velocity_at(3e-3)[1] == -2.0
    w0 = WallSpec("w", np.zeros(3), np.array([0.0, -1.0, 0.0]), 0, 1.0, 0.0, 0.5,
                  velocity=np.array([0.0, -2.0, 0.0]))
    assert w0.point_at(1e-3)[1] == -2e-3 and w0.velocity_at(0.0)[1] == -2.0


def test_moving_platen_compresses_a_column_with_its_elastic_stiffness():
    # A 10 mm x 20 mm plane-strain column on a fixed base, a rigid platen
    # coming down at 0.5 m/s (0.01 % of the wave speed). Stress waves of
    # amplitude rho c v = 23 MPa ride on the ramp; the slope of platen force
    # against platen displacement, fitted after the first 6 transit times
    # (20 us), is the plane-strain uniaxial stiffness E/(1 - nu^2) * W / H
    # (H = 19 mm between the fixed row and the top row). Measured with the
    # gradient correction: +4.2 % (the bulk penalty spring, alpha = 10, adds
    # < 1 % compliance); tolerance 6 %. Without the correction the 10-particle
    # wide column is 14.5 % too soft (kernel deficiency at its free sides).
    text = f"""
[run]
dimension = 2
t_end = 1.0
[sph]
correction = true
{ELASTIC.format(rho=7800.0, E=2e11, nu=0.3)}
[[body]]
name = "col"
material = "m"
dx = 1e-3
geometry = {{ shape = "box", lo = [0, 0], hi = [0.01, 0.02] }}
[[set]]
name = "base"
region = {{ shape = "box", lo = [-1, -1], hi = [1, 0.001] }}
[[boundary]]
set = "base"
type = "fixed"
[[wall]]
name = "platen"
point = [0, 0.02]  # touching the top row (centres at 19.5 mm, contact at 0.5 dx)
normal = [0, -1]
velocity = [0, -0.5]
stiffness = "bulk"
alpha = 10.0
"""
    s, _ = _solver(text)
    recs = []
    while s.t < 6e-5:
        recs.append(step(s))
    d = np.array([r.get("d_wall_platen", 0.0) for r in recs])
    f = np.array([r["F_wall_platen"] for r in recs])
    t = np.array([r["time"] for r in recs])
    assert d[-1] == pytest.approx(0.5 * t[-1], rel=1e-12)
    k_expect = 2e11 / (1 - 0.3**2) * 0.01 / 0.019
    late = t > 2e-5
    slope = np.polyfit(d[late], f[late], 1)[0]
    assert slope == pytest.approx(k_expect, rel=0.06)


# ------------------------------------------------------ free two-body impact
def test_momentum_conserved_in_free_collision():
    # Two discs of different size and speed collide with nothing else in the
    # model: total linear momentum is conserved to round-off (antisymmetric
    # pair forces), relative tolerance 1e-12 of sum m |v|.
    text = f"""
[run]
dimension = 2
t_end = 1.0
{ELASTIC.format(rho=1000.0, E=1e7, nu=0.3)}
[[body]]
name = "a"
material = "m"
dx = 1e-3
velocity = [8.0, 1.0, 0]
geometry = {{ shape = "cylinder", centre = [-0.0115, 0.002, 0], radius = 0.01 }}
[[body]]
name = "b"
material = "m"
dx = 1e-3
velocity = [-4.0, 0, 0]
geometry = {{ shape = "ring", centre = [0.0085, 0, 0], inner_radius = 0.003, outer_radius = 0.007 }}
"""
    s, _ = _solver(text)
    p0 = (s.part("sph").kin.m[:, None] * s.part("sph").kin.v).sum(axis=0)
    scale = (s.part("sph").kin.m * np.linalg.norm(s.part("sph").kin.v, axis=1)).sum()
    body_a = s.part("sph").kin.body == 0
    pa0 = (s.part("sph").kin.m[body_a, None] * s.part("sph").kin.v[body_a]).sum(axis=0)
    while s.t < 0.002:
        s.step()
    p1 = (s.part("sph").kin.m[:, None] * s.part("sph").kin.v).sum(axis=0)
    assert np.abs(p1 - p0).max() < 1e-12 * scale
    pa1 = (s.part("sph").kin.m[body_a, None] * s.part("sph").kin.v[body_a]).sum(axis=0)
    assert abs(pa1[0] - pa0[0]) > 0.1 * abs(pa0[0])  # they did collide


# --------------------------------------------- thesis 3.1: two passing boxes
def _boxes(gap_in_dx, dx=0.5e-3):
    h = 1.2 * dx
    gap = gap_in_dx * dx
    top = 10e-3
    return f"""
[run]
dimension = 2
t_end = 1.0
[sph]
h_factor = 1.2
[sph.viscosity]
alpha = 1.0
beta = 2.0
{ELASTIC.format(rho=7850.0, E=200e9, nu=0.3)}
[[body]]
name = "lower"
material = "m"
dx = {dx}
velocity = [300.0, 0, 0]
geometry = {{ shape = "box", lo = [0, 0, 0], hi = [10e-3, 10e-3, 0] }}
[[body]]
name = "upper"
material = "m"
dx = {dx}
velocity = [-300.0, 0, 0]
geometry = {{ shape = "box", lo = [5e-3, {top - dx + gap}, 0], hi = [15e-3, {2 * top - dx + gap}, 0] }}
"""


@pytest.mark.parametrize("gap_in_dx,interacts", [(2.4, False), (1.0, True)])
def test_thesis_two_boxes(gap_in_dx, interacts):
    # Thesis sec. 3.1: with h = 1.2 dx and support 2h = 2.4 dx, boxes whose
    # facing particle rows are 2.4 dx apart never see each other (lateral
    # momentum exchanged exactly zero), at 1.0 dx apart they interact.
    s, _ = _solver(_boxes(gap_in_dx))
    lower = s.part("sph").kin.body == 0
    while s.t < 12e-6:
        s.step()
    py = (s.part("sph").kin.m[lower] * s.part("sph").kin.v[lower, 1]).sum()
    scale = (s.part("sph").kin.m[lower] * 300.0).sum()
    if interacts:
        assert abs(py) > 1e-6 * scale
    else:
        assert py == 0.0


def test_default_guard_box_has_the_same_margin_in_every_direction():
    # A flat 3D plate (100 x 100 x 10 mm): the default box (margin 1) is
    # expanded by 1 x the largest side (100 mm) on every side, also through
    # the thickness, so debris squeezed out of the flat faces does not stop
    # the run after 10 mm. Exact: corners are sums of lattice coordinates.
    deck = loads_deck(f"""
[run]
dimension = 3
t_end = 1e-3
{ELASTIC.format(rho=2400.0, E=30e9, nu=0.2)}
[[body]]
name = "plate"
material = "m"
dx = 0.01
geometry = {{ shape = "box", lo = [0, 0, 0], hi = [0.1, 0.1, 0.01] }}
""")
    model = build_model(deck)
    x = model.particles.x
    lo_b, hi_b = x.min(axis=0), x.max(axis=0)
    side = np.max(hi_b - lo_b)
    assert np.allclose(lo_b - model.domain_lo, side, rtol=1e-12, atol=0)
    assert np.allclose(model.domain_hi - hi_b, side, rtol=1e-12, atol=0)


def test_side_view_takes_the_largest_value_across_the_width():
    # cells of 10 mm: two particles in cell (x 0, z 1) at different y keep the
    # larger value, an empty cell is NaN, and the image is (nz, nx)
    from sphdyn.analysis.fragments import side_view_max

    x0 = np.array([[0.005, 0.005, 0.015], [0.005, 0.025, 0.015], [0.015, 0.0, 0.005]])
    img = side_view_max(x0, np.array([0.2, 0.7, 1.0]), 0.01)
    assert img.shape == (2, 2)
    assert img[1, 0] == 0.7 and img[0, 1] == 1.0
    assert np.isnan(img[0, 0]) and np.isnan(img[1, 1])


def test_plan_view_takes_the_largest_value_through_the_thickness():
    # the same particles seen along z (axes x, y): cells (x 0, y 0), (x 0,
    # y 2) and (x 1, y 0)
    from sphdyn.analysis.fragments import projected_max

    x0 = np.array([[0.005, 0.005, 0.015], [0.005, 0.025, 0.015], [0.015, 0.0, 0.005],
                   [0.006, 0.004, 0.005]])
    img = projected_max(x0, np.array([0.2, 0.7, 1.0, 0.1]), 0.01, (0, 1))
    assert img.shape == (3, 2)
    assert img[0, 0] == 0.2 and img[2, 0] == 0.7 and img[0, 1] == 1.0
    assert np.isnan(img[1, 0]) and np.isnan(img[1, 1]) and np.isnan(img[2, 1])
