"""The architecture's mechanisms: growable state, events, restart across them,
and a part and an interaction added from outside the package (docs/architecture.md).
"""

import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.events import InjectParticles
from sphdyn.io import read_checkpoint, read_frame, read_history_csv
from sphdyn.simulation import Simulation
from sphdyn.state import STATE, WORK, ArrayStore, Kinematics
from sphdyn.stepper import Stepper
from decks import SMALL_DISC
from stepping import build_stepper
from toys import PointMasses, UniformField


T_INJECT = 1.0e-3


def _inject():
    """Five particles resting on the top of the disc, moving with it (at 1 ms
    the disc has moved down 5 mm and is in contact with the floor)."""
    x = np.array([[k * 1e-3, 0.0123 - 5e-3, 0.0] for k in range(-2, 3)])
    return InjectParticles("drop", T_INJECT, x, velocity=[0.0, -1.0, 0.0], template=0)


#: the injected particles bring energy from nowhere (a mechanism test, with
#: the template's stress, into the disc's neighbourhood): the energy guard off
GUARD_OFF = ('[run]', '[run]\nenergy_error_action = "off"')


def _deck(t_end="2 ms", ck=0):
    return loads_deck(SMALL_DISC.format(t_end=t_end, ck=ck).replace(*GUARD_OFF))


# ------------------------------------------------------------------ the store
def test_store_grows_every_array_and_keeps_the_data():
    s = ArrayStore(3)
    a = s.add("a", (3,), kind=STATE)
    s.add("b", (), np.int8, fill=7)
    a[:] = np.arange(9.0).reshape(3, 3)
    seen = []
    s.on_grow(lambda n0, n1: seen.append((n0, n1)))
    rows = s.grow(2)
    assert rows == slice(3, 5) and seen == [(3, 5)]
    assert s.n == 5 and s.a.shape == (5, 3) and s.b.shape == (5,)
    assert np.array_equal(s.a[:3], np.arange(9.0).reshape(3, 3))
    assert np.all(s.a[3:] == 0.0) and np.all(s.b == 7)  # fill values in new rows
    assert s.capacity >= 5 and s.a.flags.c_contiguous
    cap = s.capacity
    s.grow(0)
    assert s.capacity == cap  # no reallocation without need
    s.add("c", (2, 2))  # registered later: sized n, grows with the rest
    assert s.c.shape == (5, 2, 2)
    assert s.names(STATE) == ["a"] and s.names(WORK) == ["b", "c"]
    view = s.a
    s.a = np.ones((5, 3))  # assignment copies into the storage: views stay valid
    assert np.all(view == 1.0)
    with pytest.raises(ValueError, match="shape"):
        s.a = np.ones((4, 3))
    with pytest.raises(ValueError, match="exists"):
        s.add("a", (2,))


def test_kinematics_has_the_common_arrays():
    k = Kinematics(4, 3)
    assert set(k.names(STATE)) == {"x", "v", "a", "a_ext", "m", "bc", "bc_v", "active"}
    assert np.all(k.active == 1)
    with pytest.raises(ValueError, match="dim"):
        Kinematics(1, 4)


# ----------------------------------------------------------------- the event
def test_injected_particles_join_every_array_group_list_and_frame(tmp_path):
    deck = _deck()
    sim = Simulation.from_deck(deck, tmp_path / "run", events=[_inject()])
    p = sim.particles
    n0, m0 = p.n, float(p.m.sum())
    sim.run()
    sph = sim.stepper.part("sph")
    assert p is sim.particles and p.n == n0 + 5
    for name in p.names():  # state and work arrays alike
        assert getattr(p, name).shape[0] == n0 + 5, name
    new = np.arange(n0, n0 + 5)
    assert np.all(p.mat[new] == p.mat[0]) and np.all(p.h0[new] == p.h0[0])
    assert float(p.m.sum()) == pytest.approx(m0 + 5 * p.m[0], rel=1e-14)
    assert np.array_equal(p.x0[new], _inject().positions)
    assert any(np.isin(new, g.idx).all() for g in sph.groups)  # in the material group
    assert sph.nl.n == n0 + 5 and np.diff(sph.nl.offsets)[new].min() > 0
    # the new particles were pushed by the disc through the kernel: they no
    # longer move at their injected -1 m/s and carry stress
    assert np.abs(p.v[new, 1] + 1.0).max() > 0.1
    assert np.abs(p.sig[new]).max() > 0.0
    assert np.isfinite(p.x).all()
    frames = sorted((tmp_path / "run/frames").glob("*.h5"))
    t_first, _, f_first, _ = read_frame(frames[0])
    t_last, _, f_last, _ = read_frame(frames[-1])
    assert f_first["position"].shape[0] == n0 and f_last["position"].shape[0] == n0 + 5
    h = read_history_csv(tmp_path / "run/history.csv")
    assert h["time"][-1] == pytest.approx(2e-3) and np.isfinite(h["E_total"]).all()


def test_injected_particles_in_a_total_lagrangian_body_get_their_reference(tmp_path):
    # The new particles join the reference lists at their birth positions;
    # the old particles keep the reference they had (here the initial one).
    text = SMALL_DISC.format(t_end="1.5 ms", ck=0).replace(
        "[output]", '[sph]\nformulation = "total_lagrangian"\n[output]').replace(*GUARD_OFF)
    sim = Simulation.from_deck(loads_deck(text), tmp_path / "tl", events=[_inject()])
    p = sim.particles
    n0, x_ref0 = p.n, p.x0.copy()
    sim.run()
    tl = sim.stepper.part("sph").tl
    new = np.arange(n0, n0 + 5)
    assert np.array_equal(tl.rows, np.arange(n0 + 5))
    assert np.array_equal(tl.X[new], _inject().positions)
    assert np.array_equal(tl.X[:n0], x_ref0)
    assert np.diff(tl.offsets)[new].min() > 0  # they have reference neighbours
    assert np.isfinite(p.x).all() and np.abs(p.sig[new]).max() > 0.0


@pytest.mark.parametrize("stop_after", [100, 400], ids=["before_event", "after_event"])
def test_restart_across_the_injection_is_bitwise(tmp_path, stop_after):
    full = Simulation.from_deck(_deck(), tmp_path / "full", events=[_inject()])
    full.run()
    n_full = full.particles.n
    part = Simulation.from_deck(_deck(ck=1000), tmp_path / "part", events=[_inject()])
    part.run(max_steps=stop_after)  # stopped: the exit checkpoint is at that step
    t_ck = read_checkpoint(tmp_path / "part/checkpoint.h5")[1]["t"]
    assert (t_ck < T_INJECT) == (stop_after == 100)
    rest = Simulation.from_directory(tmp_path / "part", events=[_inject()])
    assert rest.particles.n == (n_full if t_ck >= T_INJECT else n_full - 5)
    rest.run()
    assert rest.particles.n == n_full
    for name, arr in full.particles.arrays().items():
        assert np.array_equal(arr, getattr(rest.particles, name)), name
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert list(h_full) == list(h_part)
    for col in h_full:
        assert np.array_equal(h_full[col], h_part[col]), col


# ------------------------------------------- a part and an interaction from outside
def test_a_part_and_an_interaction_from_outside_the_package():
    # Point masses under a uniform acceleration g: leapfrog is exact for a
    # constant acceleration at a constant step, x(t) = x0 + v0 t + g t^2 / 2
    # to round-off (1e-12 of the travel). The kick books the work of the
    # interaction accelerations a_ext as m a . (v_old + v_new)/2 dt_kick, which
    # is exactly the change of the half-step kinetic energy; so -E_contact
    # equals 1/2 m |v|^2 - 1/2 m |v0|^2 to round-off (1e-12 relative). A wrong
    # factor in the booking (or a sign) fails that.
    x0 = np.array([[0.1, 0.0, 0.0], [0.2, 0.1, 0.0]])
    v0 = np.array([[1.0, 2.0, 0.0], [0.0, -1.0, 0.0]])
    m = np.array([2.0, 3.0])
    balls = PointMasses(x0.copy(), v0.copy(), m)
    g = np.array([0.0, -9.81, 0.0])
    field = UniformField(balls, g)
    s = Stepper([balls], [field], dt_max=1e-3)
    for _ in range(200):
        s.step()
    t = s.t
    assert t == pytest.approx(0.2)
    exact = x0 + v0 * t + 0.5 * g * t * t
    assert np.abs(balls.kin.x - exact).max() < 1e-12 * np.abs(exact - x0).max()
    # v is the half-step velocity of the last kick, at t - dt/2
    assert np.allclose(balls.kin.v, v0 + g * (t - 0.5e-3), rtol=0, atol=1e-12)
    gained = 0.5 * float((m * (balls.kin.v ** 2).sum(axis=1)).sum()
                         - (m * (v0 ** 2).sum(axis=1)).sum())
    rec = s.record()
    assert -rec["E_contact"] == pytest.approx(gained, rel=1e-12)
    assert field.kicks == 200 and rec["kicks"] == 200.0


def test_another_part_leaves_the_sph_part_bitwise_unchanged():
    # The same disc stepped alone and beside the falling point masses (which
    # impose no step limit): its particles must end bitwise identical.
    alone = build_stepper(_deck())
    s = build_stepper(_deck())
    balls = PointMasses(np.zeros((2, 3)), np.ones((2, 3)), np.ones(2))
    both = Stepper([s.part("sph"), balls],
                   s.interactions + [UniformField(balls, [0.0, -9.81, 0.0])])
    for _ in range(100):
        alone.step()
        both.step()
    for name, arr in alone.part("sph").kin.arrays().items():
        assert np.array_equal(arr, getattr(both.part("sph").kin, name)), name


def test_the_step_is_the_smallest_of_parts_interactions_and_dt_max():
    # A bulk-modulus wall (paper eq. 9) limits the step to half its spring's
    # 2 sqrt(m/k): in 2D k = alpha K (A/L = 1 per unit depth) and the nominal
    # inertia is rho0 dx^2, so stable_dt = sqrt(rho0 dx^2 / (alpha K)) with
    # K = E / (3 (1 - 2 nu)) of the rubber. A mass-based wall (eq. 8) has none.
    text = SMALL_DISC.format(t_end="1 ms", ck=0).replace(
        'normal = [0, 1, 0]', 'normal = [0, 1, 0]\nstiffness = "bulk"')
    deck = loads_deck(text)
    s = build_stepper(deck)
    w = s.interactions[0]
    K = 1e7 / (3.0 * (1.0 - 2 * 0.3))
    expected = np.sqrt(1000.0 * 1e-6 / (deck.wall[0].alpha * K))
    assert w.stable_dt() == pytest.approx(expected, rel=1e-12)
    part_dt = s.part("sph").stable_dt()[0]
    assert s.stable_dt()[0] == pytest.approx(min(part_dt, expected), rel=1e-12)
    s.dt_max = 0.5 * min(part_dt, w.stable_dt())
    assert s.stable_dt()[0] == s.dt_max
    mass = build_stepper(_deck())
    assert mass.interactions[0].stable_dt() == np.inf
