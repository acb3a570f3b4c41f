"""Selective mass scaling (sphdyn.mass_scaling): where the mass goes, how much, what it does.

What is pinned here, with its tolerance:

* the added mass is exactly where and as much as the formula says (1e-12,
  round-off): a particle's own, :math:`m (1/r^2 - 1)` with the wave-speed
  factor :math:`r` solved from the CFL step; an element's
  :math:`(g^2 - 1) m_e` shared by its nodes as its own mass is (``1/nen``);
  a sublayer slave's on its node, none on the slave;
* the step reaches the target (1e-12) and items above it are left alone;
* what it does: a truss bar scaled four-fold everywhere carries its wave at
  half the speed (the half-amplitude front within two elements of c t / 2,
  where the unscaled bar's is within two elements of c t); momentum of
  free SPH bodies stays exact (1e-12 of the initial momentum); the energy
  balance, with the added mass in the kinetic energy, closes as well as the
  unscaled run's (within 1e-3 of the energy put in);
* the limit: a target needing more than ``max_added`` of the model's mass
  is refused naming the part given the most and the largest target within
  the limit, and that target is accepted, within the limit (to 1e-6);
* a beam element's rotary inertia scales with its mass (1e-12); an eroded
  element takes its added mass off its nodes and erosion's books count its
  inertia (1e-12);
* a tied, hybrid or embedded slave's added mass lands on its masters with the
  weights of its own mass (1e-12), none on the slave;
* a restart continues a mass-scaled run with the same bits;
* the deck: an unknown name in ``parts`` is refused naming the field.
"""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from decks import STEEL

CONCRETE = """
[[material]]
name = "concrete"
model = "elastic"
density = 2400.0
E = "30 GPa"
nu = 0.2
"""


def _scaling(target: str | None, extra: str = "") -> str:
    if target is None:
        return ""
    return f'[time.mass_scaling]\ntarget = "{target}"\n{extra}\n'


# ------------------------------------------------------------- truss bar
TRUSS = """
[run]
dimension = 3
t_end = "1 ms"
{materials}
[[mesh]]
name = "bar"
material = "steel"
element = "truss"
line = {{ start = [0, 0, 0], end = [1, 0, 0], divisions = 200 }}
section = {{ shape = "circle", diameter = "10 mm" }}
[[set]]
name = "end"
mesh = "bar"
region = {{ shape = "box", lo = [-0.001, -1, -1], hi = [0.001, 1, 1] }}
[[boundary]]
set = "end"
type = "velocity"
velocity = ["1 m/s", 0, 0]
ramp_time = "10 us"
ramp = "smooth"
{scaling}
[output]
progress = false
vtk = false
"""


def _truss(scaling: str = ""):
    return build_stepper(loads_deck(TRUSS.format(materials=STEEL, scaling=scaling)))


def test_every_truss_element_scaled_fourfold_halves_the_wave_speed():
    """Target twice the bar's step: g = 2 on every element, so each node's
    added mass is 3 times its own (1e-12); the half-amplitude front at
    t = L / (2c) stands at c (t - t_r/2) unscaled and half of it scaled (t_r
    the end's smooth velocity ramp, its half-amplitude time t_r/2; within two
    elements)."""
    plain = _truss()
    dt = plain.dt0
    st = _truss(_scaling(f"{2 * dt!r} s", "max_added = 5"))
    bar, bar0 = st.part("bar"), plain.part("bar")
    assert st.dt0 == pytest.approx(2 * dt, rel=1e-12)
    assert np.allclose(bar.elements.dt_mass, 2.0, rtol=1e-12)
    assert np.allclose(bar.kin.m_added, 3.0 * bar.kin.m, rtol=1e-12)
    c = np.sqrt(200e9 / 7850.0)
    t_front = 0.5 / c
    for s in (plain, st):
        while s.t < t_front:
            s.step(t_stop=t_front)
    t_half = 0.5 * 10e-6
    for s, at in ((plain, c * (t_front - t_half)), (st, 0.5 * c * (t_front - t_half))):
        kin = s.part("bar").kin
        order = np.argsort(kin.x0[:, 0])
        front = kin.x0[order, 0][np.flatnonzero(kin.v[order, 0] > 0.5)[-1]]
        assert front == pytest.approx(at, abs=2 * 1.0 / 200)
    # the books close as well with the added mass as without (the velocity
    # boundary puts the energy in): within 1e-3 of the work done
    for s in (plain, st):
        r = s.record()
        assert abs(r["E_total"]) < 1e-3 * abs(r["W_external"])
    assert st.record()["mass_added_bar"] == pytest.approx(3.0 * bar0.kin.m.sum(), rel=1e-12)


# ------------------------------------------------------------ SPH bodies
TWO_BODIES = """
[run]
dimension = 2
t_end = "1 ms"
{materials}
[[body]]
name = "soft"
material = "concrete"
dx = "2 mm"
geometry = {{ shape = "box", lo = [0, 0], hi = ["40 mm", "20 mm"] }}
[[body]]
name = "stiff"
material = "steel"
dx = "2 mm"
velocity = ["2 m/s", "1 m/s"]
geometry = {{ shape = "box", lo = ["40 mm", 0], hi = ["60 mm", "20 mm"] }}
{scaling}
[output]
progress = false
vtk = false
"""


def _bodies(scaling: str = ""):
    return build_stepper(loads_deck(TWO_BODIES.format(materials=CONCRETE + STEEL,
                                                      scaling=scaling)))


def _momentum(s) -> np.ndarray:
    p = s.part("sph").p
    return (p.inertia()[:, None] * p.v).sum(axis=0)


def test_steel_particles_take_their_mass_and_the_step_reaches_the_target():
    plain = _bodies()
    p0 = plain.part("sph").p
    soft = p0.body == 0
    cfl = 0.3
    # the concrete's own step: the target, above every steel particle's
    target = float(np.min(cfl * p0.h[soft] / (p0.c[soft] + np.linalg.norm(p0.v[soft], axis=1))))
    assert plain.dt0 < 0.8 * target
    st = _bodies(_scaling(f"{target!r} s", "max_added = 2"))
    p = st.part("sph").p
    stiff = p.body == 1
    assert st.dt0 == pytest.approx(target, rel=1e-12)
    # the concrete is left alone (its slowest particle set the target: to
    # round-off, 1e-12)
    assert np.allclose(p.c_mass[soft], 1.0, rtol=0, atol=1e-12)
    assert np.all(p.m_added[soft] <= 1e-11 * p.m[soft])
    r = p.c_mass[stiff]
    assert np.all(r < 1.0)
    speed = np.linalg.norm(p.v[stiff], axis=1)
    # each steel particle's CFL step with the factor is the target
    assert np.allclose(cfl * p.h[stiff] / (r * p.c[stiff] + speed), target, rtol=1e-12)
    assert np.allclose(p.m_added[stiff], p.m[stiff] * (1.0 / r ** 2 - 1.0), rtol=1e-12)
    assert st.mass_scaling.summary()["parts"]["sph"]["items_scaled"] == int(stiff.sum())


def test_free_bodies_keep_their_momentum_and_energy():
    """No external force: the momentum of the inertia is exact to round-off
    (1e-12 of the initial); the energy moves between kinetic and internal,
    and the total drifts (the bodies start with a velocity jump between
    them) by no more than the unscaled run's drift times 1.5 and below 1 %
    of the initial kinetic energy."""
    plain = _bodies()
    p0 = plain.part("sph").p
    soft = p0.body == 0
    target = float(np.min(0.3 * p0.h[soft] / p0.c[soft]))
    drifts = []
    for s in (plain, _bodies(_scaling(f"{target!r} s", "max_added = 2"))):
        m0 = _momentum(s)
        s.step()
        e0 = s.record()["E_total"]
        for _ in range(300):
            s.step()
        r = s.record()
        assert np.allclose(_momentum(s), m0, rtol=0, atol=1e-12 * np.abs(m0).max())
        assert r["E_internal"] > 0.1 * r["E_kinetic"]  # the bodies did deform
        drifts.append(abs(r["E_total"] - e0) / e0)
    assert drifts[0] < 0.01 and drifts[1] < max(1.5 * drifts[0], 1e-4)


def test_a_restart_of_a_scaled_run_continues_with_the_same_bits():
    from stepping import restarted_pair

    p0 = _bodies().part("sph").p
    target = float(np.min(0.3 * p0.h / p0.c))
    deck = loads_deck(TWO_BODIES.format(materials=CONCRETE + STEEL,
                                        scaling=_scaling(f"{target!r} s", "max_added = 2")))

    def advance(st):
        for _ in range(20):
            st.step()

    st, st2 = restarted_pair(deck, advance, 20)
    p, p2 = st.part("sph").p, st2.part("sph").p
    assert np.array_equal(p.x, p2.x) and np.array_equal(p.v, p2.v)
    assert st.record()["E_total"] == st2.record()["E_total"]


# --------------------------------------------------------- solid elements
BLOCK = """
[run]
dimension = 3
t_end = "1 ms"
{materials}
[[mesh]]
name = "block"
material = "steel"
block = {{ lo = [0, 0, 0], hi = ["40 mm", "20 mm", "20 mm"], divisions = [4, 2, 2] }}
velocity = ["1 m/s", 0, 0]
{scaling}
[output]
progress = false
vtk = false
"""


def test_every_hexahedron_scaled_gives_its_nodes_its_share():
    """Target 1.5 times the mesh's step: each element takes g_e = target /
    (C dt_e) (1.5 on the controlling ones), and each node (g_e^2 - 1) m_e / 8
    from each of its elements (1e-12); a regular block's elements share one
    step (with the hourglass control too: its terms leave an undistorted
    element's step alone, up to the square root of a round-off in its
    subspace overlap, 1e-6), so every node takes 1.25 times its own mass."""
    for hourglass in ("", "hourglass_coefficient = 0.0\n"):
        text = BLOCK.replace('velocity = ["1 m/s", 0, 0]\n',
                             'velocity = ["1 m/s", 0, 0]\n' + hourglass)
        plain = build_stepper(loads_deck(text.format(materials=STEEL, scaling="")))
        target = 1.5 * plain.dt0
        st = build_stepper(loads_deck(text.format(materials=STEEL, scaling=_scaling(
            f"{target!r} s", "max_added = 2"))))
        part, p0 = st.part("block"), plain.part("block")
        q, el = part.kin, part.el
        assert st.dt0 == pytest.approx(target, rel=1e-12)
        g = np.maximum(target / (p0.s.cfl * p0.el.dt_el), 1.0)
        assert np.allclose(el.dt_mass, g, rtol=1e-12) and g.max() == pytest.approx(1.5)
        share = np.zeros(q.n)
        np.add.at(share, el.conn.ravel(), np.repeat((g * g - 1.0) * el.m / 8, 8))
        assert np.allclose(q.m_added, share, rtol=1e-12)
        tol = 1e-12 if hourglass else 1e-6
        assert np.allclose(g, 1.5, rtol=tol)
        assert np.allclose(q.m_added, 1.25 * q.m, rtol=3 * tol)


# --------------------------------------------------------------- slaves
def test_a_sublayer_particle_s_mass_goes_to_its_node():
    """Only the sublayer's particles chosen: each bar node takes its
    particle's m (1/r^2 - 1) (1e-12), the particles none (their node carries
    their inertia), the concrete none."""
    from test_sublayer import deck_text

    p0 = build_stepper(loads_deck(deck_text(sets=""))).part("sph").p
    target = float(np.min(0.3 * p0.h[p0.body == 0] / p0.c[p0.body == 0]))
    st = build_stepper(loads_deck(deck_text(sets=_scaling(
        f"{target!r} s", 'parts = ["bar_sublayer"]\nmax_added = 0.5'))))
    p, bar = st.part("sph").p, st.part("bar")
    coupling = next(i for i in st.interactions if i.name.startswith("bar"))
    rows, nodes = coupling.rows, coupling.nodes
    r = p.c_mass[rows]
    assert np.all(r < 1.0) and np.all(p.c_mass[p.body == 0] == 1.0)
    assert "m_added" not in p.names()  # the slaves' mass is on the nodes
    assert np.allclose(bar.kin.m_added[nodes], p.m[rows] * (1.0 / r ** 2 - 1.0), rtol=1e-12)
    assert st.dt0 == pytest.approx(target, rel=1e-12)
    summary = st.mass_scaling.summary()
    assert summary["parts"]["bar"]["added_kg"] == pytest.approx(
        float(np.sum(p.m[rows] * (1.0 / r ** 2 - 1.0))), rel=1e-12)
    assert summary["parts"]["sph"]["added_kg"] == 0.0


# ----------------------------------------------------------- the limit
def test_a_target_beyond_the_limit_is_refused_with_the_part_and_the_largest_target():
    """The steel body is 62 % of the model's mass; the concrete's step as the
    target adds 91 % of it: refused at 0.1, naming the part and a target that
    is then accepted, its added mass within the limit and no more than 1e-3
    below it."""
    plain = _bodies()
    p0 = plain.part("sph").p
    target = float(np.min(0.3 * p0.h[p0.body == 0] / p0.c[p0.body == 0]))
    with pytest.raises(ValueError) as err:
        _bodies(_scaling(f"{target!r} s", "max_added = 0.1"))
    text = str(err.value)
    assert "part 'sph'" in text and "max_added = 0.1" in text
    at_most = float(text.split("at most ")[1].split(" s")[0])
    assert plain.dt0 < at_most < target
    st = _bodies(_scaling(f"{at_most!r} s", "max_added = 0.1"))
    fraction = st.mass_scaling.summary()["fraction"]
    assert 0.1 * (1 - 1e-3) < fraction <= 0.1


def test_an_unknown_part_name_is_refused_naming_the_field():
    with pytest.raises(DeckError) as err:
        loads_deck(TWO_BODIES.format(materials=CONCRETE + STEEL,
                                     scaling=_scaling("1 us", 'parts = ["stiffer"]')))
    assert "time.mass_scaling.parts" in str(err.value)
    assert "stiff" in str(err.value)


def _coupled(kind: str, scaling: str):
    if kind == "embedded":
        from test_embedded import BAR, COMPOSITE

        return build_stepper(loads_deck(COMPOSITE.replace("{bar}", BAR + scaling)))
    from test_tied_hybrid import bar3d_text

    return build_stepper(loads_deck(bar3d_text(kind) + scaling))


@pytest.mark.parametrize("kind", ["tied", "hybrid", "embedded"])
def test_a_coupling_s_slaves_pass_their_added_mass_to_their_masters(kind):
    """Everything scaled to 1.5 times the model's step: each slave's added mass
    (its part's own, :meth:`scale_mass`) lands on its masters with the weights
    its own mass went with (1e-12), none stays on a slave, and the model's
    added mass is the parts' sum (1e-12)."""
    target = 1.5 * _coupled(kind, "").dt0
    st = _coupled(kind, _scaling(f"{target!r} s", "max_added = 10"))
    assert st.dt0 == pytest.approx(target, rel=1e-12)
    tables = {id(t): t for part in st.parts
              for t in (part.kin, getattr(part.kin, "rot", None)) if t is not None}
    own = {}  # each table's added mass before the slaves' went to their masters
    for part in st.parts:
        for name, arr in part.scale_mass(target).items():
            own[id(part.kin if name == "kin" else part.kin.rot)] = arr
    expected = {k: v.copy() for k, v in own.items()}
    maps = [i.slave_map() for i in st.interactions if hasattr(i, "slave_map")]
    assert maps
    for slaves, rows, masters, conn, weights in maps:
        np.add.at(expected[id(masters)], conn.ravel(),
                  (weights * own[id(slaves)][rows][:, None]).ravel())
        expected[id(slaves)][rows] = 0.0
    for k, arr in expected.items():
        got = tables[k].m_added if "m_added" in tables[k].names() else np.zeros_like(arr)
        assert np.allclose(got, arr, rtol=1e-12, atol=1e-12 * max(arr.max(), 1e-300))
    for slaves, rows, *_ in maps:
        if "m_added" in slaves.names():
            assert np.all(slaves.m_added[rows] == 0.0)
    added = sum(v["added_kg"] for v in st.mass_scaling.summary()["parts"].values())
    translations = sum(float(own[id(part.kin)].sum()) for part in st.parts)
    assert added == pytest.approx(translations, rel=1e-12)


def test_an_eroded_element_takes_its_added_mass_and_its_inertia_s_books_with_it():
    """Erosion's books of a scaled element count the inertia of its node shares,
    ``g^2 m_e / nen`` each (the block moves at 1 m/s: 1/2 g^2 m_e, 1e-12), and
    eroding it takes ``(g^2 - 1) m_e`` off its nodes' added mass (1e-12)."""
    target = 1.5 * build_stepper(loads_deck(BLOCK.format(materials=STEEL, scaling=""))).dt0
    st = build_stepper(loads_deck(BLOCK.format(materials=STEEL, scaling=_scaling(
        f"{target!r} s", "max_added = 2"))))
    block = st.part("block")
    m_e = float(block.el.m[0])
    _, kinetic, _ = block.element_books(np.array([0]))
    assert kinetic[0] == pytest.approx(0.5 * 1.5 ** 2 * m_e, rel=1e-12)
    before = block.kin.m_added.sum()
    block.erode(np.array([0]))
    assert before - block.kin.m_added.sum() == pytest.approx(1.25 * m_e, rel=1e-12)


BEAM = TRUSS.replace('element = "truss"', 'element = "beam"')


def test_every_beam_element_scaled_takes_mass_and_rotary_inertia_alike():
    """Target twice a beam's step: g = 2 on every element, so each node takes
    three times its own mass and three times its rotary inertia (1e-12), and
    the step is the target."""
    dt = build_stepper(loads_deck(BEAM.format(materials=STEEL, scaling=""))).dt0
    st = build_stepper(loads_deck(BEAM.format(materials=STEEL, scaling=_scaling(
        f"{2 * dt!r} s", "max_added = 5"))))
    kin = st.part("bar").kin
    assert st.dt0 == pytest.approx(2 * dt, rel=1e-12)
    assert np.allclose(kin.m_added, 3.0 * kin.m, rtol=1e-12)
    assert np.allclose(kin.rot.m_added, 3.0 * kin.rot.m, rtol=1e-12)
