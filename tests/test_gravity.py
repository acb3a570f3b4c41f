"""[run] gravity: a body load m g on every particle and node with mass.

Free fall is exact in the leapfrog (constant acceleration, any step
sequence); a column standing on its base under gravity settles to a base
reaction equal to its weight; gravity's work is external work, booked in
W_external (the energy balance closes), and reported as W_gravity_<part>.
"""

import math

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.interactions import Gravity
from sphdyn.interactions.gravity import add_gravity, gravity_work
from sphdyn.state import BC_SLAVE

from decks import STEEL

G = 9.81

SPH = """
[run]
dimension = 3
t_end = "1 ms"
{gravity}
{steel}[[body]]
name = "ball"
material = "steel"
dx = "2 mm"
velocity = [0, "1 m/s", 0]
geometry = {{ shape = "sphere", centre = [0, 0, 0], radius = "5 mm" }}
[[mesh]]
name = "block"
material = "steel"
block = {{ lo = ["20 mm", 0, 0], hi = ["30 mm", "10 mm", "10 mm"], divisions = [2, 2, 2] }}
velocity = [0, "1 m/s", 0]
[output]
progress = false
vtk = false
"""


def _sph(gravity: str) -> str:
    return SPH.format(gravity=gravity, steel=STEEL)


def test_gravity_is_read_with_its_units_and_is_off_by_default():
    deck = loads_deck(_sph('gravity = [0, 0, "-9.81 m/s^2"]'))
    assert deck.run.gravity == (0.0, 0.0, -G)
    assert loads_deck(_sph("")).run.gravity is None
    assert not any(isinstance(i, Gravity)
                   for i in build_stepper(loads_deck(_sph(""))).interactions)
    with pytest.raises(DeckError, match="run.gravity"):
        loads_deck(_sph('gravity = [0, 0, "-9.81 m/s"]'))


def test_free_fall_is_exact_and_its_work_is_external():
    """Particles and nodes fall together: a rigid translation carries no
    stress, so every item's displacement is v0 t + g t^2 / 2 and its velocity
    in the middle of the last step v0 + g (t - dt/2), exactly for the leapfrog under a constant
    acceleration (the steps vary as the speed grows): 1e-9 relative,
    round-off over ~1000 steps. The work booked is external (E_contact stays
    0, W_external is W_gravity) and equals the loss of potential energy at
    the last kick, M g dz_c, to less than gravity's work over one step (the
    kicks book m g.v dt at mid-kick velocities, a midpoint rule of the exact
    integral, off by O(dt) at the ends); so does the balance E_total, which
    starts at the kinetic energy of the 1 m/s sideways motion."""
    s = build_stepper(loads_deck(_sph('gravity = [0, 0, "-9.81 m/s^2"]')))
    grav = [i for i in s.interactions if isinstance(i, Gravity)]
    assert len(grav) == 2  # one per part
    x0 = [q.kin.x.copy() for q in s.parts]
    t_end = 2e-3
    while s.t < t_end:
        s.step(t_end)
    t = s.t
    assert s.step_count > 500
    for q, x in zip(s.parts, x0):
        d = q.kin.x - x
        assert np.allclose(d[:, 2], -0.5 * G * t * t, rtol=1e-9, atol=0)
        assert np.allclose(d[:, 1], 1.0 * t, rtol=1e-9, atol=0)
        # the velocity held is the last step's mid-step one
        assert np.allclose(q.kin.v[:, 2], -G * (t - 0.5 * s.dt_step), rtol=1e-9, atol=0)
    rec = s.record()  # at the last kick, the start of the last step
    tk = t - s.dt_step
    mass = sum(q.kin.m.sum() for q in s.parts)
    drop = mass * G * 0.5 * G * tk * tk
    one_step = mass * G * G * tk * s.dt_step  # gravity's work over one step
    w = sum(rec[f"W_{g.name}"] for g in grav)
    assert abs(w - drop) < one_step and one_step < 1e-3 * drop
    assert rec["W_external"] == pytest.approx(w, rel=1e-12)
    assert abs(rec["E_contact"]) < 1e-12 * drop
    assert abs(rec["E_total"] - 0.5 * mass * 1.0) < one_step


COLUMN = """
[run]
dimension = 3
t_end = "4 ms"
gravity = [0, 0, "-9.81 m/s^2"]
[[material]]
name = "steel"
model = "elastic"
density = 7850.0
E = "200 GPa"
nu = 0.0
[[mesh]]
name = "column"
material = "steel"
block = { lo = [0, 0, 0], hi = ["20 mm", "20 mm", "100 mm"], divisions = [2, 2, 10] }
damping = "1.6e5 1/s"
[[set]]
name = "base"
mesh = "column"
region = { shape = "box", lo = [-1, -1, -1], hi = [1, 1, "1 mm"] }
[[boundary]]
set = "base"
type = "fixed"
[output]
progress = false
vtk = false
"""


def test_a_column_on_its_base_settles_to_carry_its_weight():
    """A steel column 20 x 20 x 100 mm (2 x 2 x 10 hexahedra, nu = 0) on a
    fixed base under gravity, damped near critically in its first axial mode
    (c = 2 omega_1, omega_1 = pi c_L / 2H = 7.9e4 1/s): after 4 ms (50
    periods) the base reaction is the weight rho g V = 3.080 N to 1e-6 (the
    damped remainder), and the lowest elements carry sigma_zz = -rho g (H -
    z_c) at their centres to 1e-3 (a linear stress field, which the uniform-
    strain hexahedra represent at their centres)."""
    s = build_stepper(loads_deck(COLUMN))
    while s.t < 4e-3:
        s.step(4e-3)
    rec = s.record()
    weight = 7850.0 * 0.02 * 0.02 * 0.1 * G
    assert rec["base_reaction_z"] == pytest.approx(weight, rel=1e-6)
    assert abs(rec["base_reaction_x"]) < 1e-9 * weight
    col = s.parts[0]
    zc = col.nodes.x[col.el.conn, 2].mean(axis=1)  # element centres
    assert np.allclose(col.pts.sig[:, 2, 2], -7850.0 * G * (0.1 - zc), rtol=1e-3, atol=0)


def test_gravity_skips_massless_items_and_slaves_and_books_their_absence():
    # add_gravity / gravity_work on four items: a free one, a zero-mass one,
    # a slave, a fixed one (loaded: the support's reaction carries its weight);
    # the work is sum m g.v dt over the loaded ones (1e-15)
    m = np.array([2.0, 0.0, 3.0, 5.0])
    bc = np.array([0, 0, BC_SLAVE, 1], np.int8)
    g = np.array([0.0, 0.0, -G])
    a = np.zeros((4, 3))
    add_gravity(m, bc, g, a)
    assert np.array_equal(a[:, 2], [-G, 0.0, 0.0, -G])
    v = np.array([[0, 0, -1.0], [0, 0, -2.0], [0, 0, -3.0], [0, 0, 0.5]])
    w = gravity_work(m, bc, g, v, 1e-3)
    assert w == pytest.approx((2.0 * G * 1.0 + 5.0 * G * -0.5) * 1e-3, rel=1e-15)
    assert math.isfinite(w)
