"""[[gauge]]: strain, point and section-force gauges at material points.

The formulas are pinned on hand-set states; a steel column settled under
gravity checks all three against its linear stress field; a run writes each
gauge at its own rate; bad gauges are refused before anything runs.
"""

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.watchers.gauges import build_gauges
from sphdyn.io.history import read_history_csv
from sphdyn.simulation import Simulation

from test_gravity import COLUMN, G

RHO, E, A, H = 7850.0, 200e9, 0.02 * 0.02, 0.1

GAUGES = """
[[gauge]]
name = "strain"
type = "strain"
points = [["10 mm", "10 mm", "20 mm"], ["10 mm", "10 mm", "80 mm"]]
every = "0.5 ms"
[[gauge]]
name = "top"
type = "point"
point = ["20 mm", "20 mm", "100 mm"]
quantities = ["displacement_z", "velocity_z"]
every = "1 ms"
[[gauge]]
name = "cut"
type = "section"
point = [0, 0, "55 mm"]
normal = [0, 0, 1]
"""


def test_gauge_formulas_on_a_set_state():
    # strain = |x_b - x_a| / |X_b - X_a| - 1, displacement x - X, section
    # force sum m (a - a_ext) over the items behind the plane (1e-15)
    s = build_stepper(loads_deck(COLUMN + GAUGES))
    strain, top, cut = build_gauges(loads_deck(COLUMN + GAUGES), s.parts)
    q = s.parts[0].kin
    (_, a), (_, b) = strain.items
    assert np.allclose(q.x0[a], [0.01, 0.01, 0.02]) and np.allclose(q.x0[b], [0.01, 0.01, 0.08])
    assert strain.length0 == pytest.approx(0.06, rel=1e-15)
    q.x[b] = q.x0[b] + [0.003, 0.0, 0.004]  # b moved by (3, 0, 4) mm
    expect = np.linalg.norm([0.003, 0.0, 0.064]) / 0.06 - 1.0
    assert strain.values(s.parts)["strain"] == pytest.approx(expect, rel=1e-14)
    (_, i), = top.items
    q.x[i, 2] = q.x0[i, 2] - 2e-3
    q.v_mid[i, 2] = -5.0
    assert top.values(s.parts) == {"displacement_z": pytest.approx(-2e-3, rel=1e-12),
                                   "velocity_z": -5.0}
    behind = q.x0[:, 2] < 0.055
    q.a[:] = 0.0
    q.a_ext[:] = 0.0
    q.a[:, 2] = np.arange(q.n)
    q.a[:, 0] = q.a_ext[:, 0] = 1.0  # all external (a holds a_ext too): left out
    f = cut.values(s.parts)
    assert f["force_z"] == pytest.approx((q.m * np.arange(q.n))[behind].sum(), rel=1e-14)
    assert f["force_x"] == 0.0 and f["force_y"] == 0.0


def test_gauges_of_a_column_settled_under_gravity(tmp_path):
    """The column of test_gravity (20 x 20 x 100 mm steel, nu = 0, damped on a
    fixed base) settles to sigma_zz = -rho g (H - z). Strain gauge from z = 20
    to 80 mm: the mean strain -rho g (H - 50 mm) / E; top point: the
    shortening -rho g H^2 / 2E; section at z = 55 mm (normal +z): the part
    above pushes down on the part below with its weight, F_z = -rho g A
    (H - 55 mm). All to 1e-3 (the elements' uniform strains hold the linear
    field at their centres, so the nodal sums are exact; the damped remainder
    is 1e-6). Each gauge samples at its own rate: strain every 0.5 ms, top
    every 1 ms, the section at the default t_end / 1000, each once per
    interval from t = 0 and once at the end."""
    sim = Simulation.from_deck(loads_deck(COLUMN + GAUGES), tmp_path)
    sim.run(progress=False)
    d = {n: read_history_csv(tmp_path / "gauges" / f"{n}.csv")
         for n in ("strain", "top", "cut")}
    assert d["strain"]["strain"][-1] == pytest.approx(-RHO * G * (H - 0.05) / E, rel=1e-3)
    assert d["top"]["displacement_z"][-1] == pytest.approx(-RHO * G * H * H / (2 * E),
                                                           rel=1e-3)
    assert abs(d["top"]["velocity_z"][-1]) < 1e-9
    assert d["cut"]["force_z"][-1] == pytest.approx(-RHO * G * A * (H - 0.055), rel=1e-3)
    for name, every in (("strain", 0.5e-3), ("top", 1e-3), ("cut", 4e-6)):
        t = d[name]["time"]
        assert t[0] == 0.0 and t[-1] == pytest.approx(4e-3, rel=1e-12)
        k = np.floor(t[:-1] / every + 1e-9)
        assert np.array_equal(k, np.arange(k.size))  # one sample per interval
        assert k.size == round(4e-3 / every)
    assert (tmp_path / "plots" / "gauges.png").exists()


@pytest.mark.parametrize("gauge, where, words", [
    ('type = "strain"\npoints = [[0, 0, "20 mm"], [0, 0, "20 mm"]]', "gauge[0]",
     "coincide"),
    ('type = "point"', "gauge[0]", "needs point"),
    ('type = "section"\npoint = [0, 0, "5 mm"]', "gauge[0]", "needs normal"),
    ('type = "strain"\npoints = [[0, 0, 0], [0, 0, "1 m"]]\nquantities = ["velocity_x"]',
     "gauge[0]", "quantities mean nothing"),
    ('type = "point"\npoint = [0, 0, 0]\nbody = "nothing"', "gauge[0].body",
     "no body named"),
])
def test_bad_gauges_are_refused_naming_the_field(gauge, where, words):
    with pytest.raises(DeckError, match=words) as err:
        loads_deck(COLUMN + f'[[gauge]]\nname = "g"\n{gauge}\n')
    assert where in str(err.value)


def test_a_gauge_point_outside_the_model_is_refused_before_the_run(tmp_path):
    deck = loads_deck(COLUMN + '[[gauge]]\nname = "g"\ntype = "point"\n'
                               'point = [0, 0, "150 mm"]\n')
    with pytest.raises(DeckError, match=r"gauge\[0\] 'g'.point.*not in the model"):
        Simulation.from_deck(deck, tmp_path / "run")
    assert not (tmp_path / "run").exists()
    deck = loads_deck(COLUMN + '[[gauge]]\nname = "g"\ntype = "section"\n'
                               'point = [0, 0, "-5 mm"]\nnormal = [0, 0, 1]\n')
    with pytest.raises(DeckError, match="behind the plane"):
        Simulation.from_deck(deck, tmp_path / "run")


def test_sphdyn_check_places_the_gauges(tmp_path, capsys):
    """``sphdyn check`` refuses a gauge point outside the model (exit 2, the
    field named) as a run would, and passes one inside."""
    from sphdyn.cli import main

    for z, ok in (("150 mm", False), ("50 mm", True)):
        path = tmp_path / "deck.toml"
        path.write_text(COLUMN + f'[[gauge]]\nname = "g"\ntype = "point"\npoint = [0, 0, "{z}"]\n')
        try:
            rc = main(["check", str(path)])
        except SystemExit as exc:
            rc = exc.code
        out = capsys.readouterr()
        if ok:
            assert rc == 0 and "1 gauges" in out.out
        else:
            assert rc == 2 and "gauge[0] 'g'.point" in out.err + out.out


def test_a_restarted_run_continues_the_gauges_and_gravity_bitwise(tmp_path):
    # Run through, and stopped after 150 steps (exit checkpoint) then
    # restarted: every gauge file and the history (with W_gravity) bitwise
    # equal; the gauges sample the same times.
    deck = COLUMN.replace('t_end = "4 ms"', 't_end = "0.5 ms"') + GAUGES.replace(
        '"0.5 ms"', '"0.05 ms"').replace('"1 ms"', '"0.1 ms"')
    Simulation.from_deck(loads_deck(deck), tmp_path / "full").run(progress=False)
    ck = deck.replace("[output]", "[output]\ncheckpoint_every = 1000")
    Simulation.from_deck(loads_deck(ck), tmp_path / "part").run(progress=False, max_steps=150)
    Simulation.from_directory(tmp_path / "part").run(progress=False)
    for f in ("gauges/strain.csv", "gauges/top.csv", "gauges/cut.csv", "history.csv"):
        a, b = (read_history_csv(tmp_path / r / f) for r in ("full", "part"))
        assert list(a) == list(b)
        for col in a:
            assert np.array_equal(a[col], b[col]), (f, col)
    assert read_history_csv(tmp_path / "full/history.csv")["W_gravity_column"][-1] > 0.0


def test_a_gauge_in_concrete_beside_a_bar_takes_the_concretes_spacing():
    """A point gauge on the pull-out block (dx 10 mm) at a lattice cell's centre
    on the bar's line: its nearest block particle is 8.66 mm away (half the
    cell's diagonal), within the block's spacing of 10 mm; a bar particle sits
    7.07 mm from that particle, which must not count as the block's spacing
    (it did: the gauge was refused). A point 12 mm above the block's top
    layer is still refused."""
    from test_sublayer import deck_text

    gauge = """
[[gauge]]
name = "g"
type = "point"
body = "block"
point = ["10 mm", "30 mm", "30 mm"]
quantities = ["displacement_z"]
"""
    deck = loads_deck(deck_text(sets="") + gauge)
    st = build_stepper(deck)
    sph = st.part("sph")
    assert len(build_gauges(deck, st.parts)) == 1
    x0 = sph.p.x0
    block = np.flatnonzero(sph.p.body == 0)
    bar = np.flatnonzero(sph.p.body == 1)
    i = block[np.argmin(np.linalg.norm(x0[block] - [0.01, 0.03, 0.03], axis=1))]
    assert np.linalg.norm(x0[i] - [0.01, 0.03, 0.03]) == pytest.approx(0.00866, abs=1e-5)
    assert np.linalg.norm(x0[bar] - x0[i], axis=1).min() == pytest.approx(0.00707, abs=1e-5)
    far = loads_deck(deck_text(sets="") + gauge.replace(
        'point = ["10 mm", "30 mm", "30 mm"]', 'point = ["10 mm", "30 mm", "67 mm"]'))
    with pytest.raises(DeckError, match="is not in body 'block'"):
        build_gauges(far, build_stepper(far).parts)
