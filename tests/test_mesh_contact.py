"""[mesh.contact]: the particles of every body meet a mesh's faces by penalty.

The coupling itself (spring, shape-function split, friction, momentum,
energy) is verified in tests/test_penalty_coupling.py; here the deck makes
it: an SPH projectile strikes a free hex block and rebounds, the pair
keeping its momentum to round-off and the block taking the impulse.
"""

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.interactions.penalty_coupling import PenaltyCoupling

from decks import STEEL

#: the free hex block struck, its [mesh.contact] and the output
TARGET = """[[mesh]]
name = "block"
material = "steel"
block = {{ lo = ["-20 mm", "-20 mm", "-20 mm"], hi = ["20 mm", "20 mm", 0], divisions = [8, 8, 4] }}
{contact}
[output]
every = "{t_end}"
progress = false
vtk = false
"""

DECK = """
[run]
dimension = 3
t_end = "{t_end}"
{steel}[[body]]
name = "ball"
material = "steel"
dx = "2 mm"
velocity = [0, 0, "-50 m/s"]
geometry = {{ shape = "sphere", centre = [0, 0, "6 mm"], radius = "5 mm" }}
""" + TARGET


def _stepper(contact="[mesh.contact]\nalpha = 0.1", t_end="80 us"):
    return build_stepper(loads_deck(DECK.format(contact=contact, t_end=t_end,
                                                steel=STEEL)))


def _momentum(s):
    return sum((q.kin.m[:, None] * q.kin.v).sum(axis=0) for q in s.parts)


def test_projectile_rebounds_from_the_block_keeping_the_momentum():
    """The ball (2 mm lattice, 50 m/s) starts 1 mm above the block: in
    80 us it meets the top face, is stopped and pushed back (its z-velocity
    turns positive), no particle ends below the face by more than the
    contact thickness (half a spacing); the ball and block keep their
    momentum to 1e-9 of the initial (round-off over ~300 steps), so the
    block carries the reversed impulse. Without [mesh.contact] the ball
    passes into the block."""
    s = _stepper()
    assert sum(isinstance(i, PenaltyCoupling) for i in s.interactions) == 1
    ball = s.parts[0]
    p0 = _momentum(s)
    while s.t < 80e-6:
        s.step(80e-6)
    assert np.abs(_momentum(s) - p0).max() < 1e-9 * np.abs(p0).max()
    vz = (ball.p.m * ball.p.v[:, 2]).sum() / ball.p.m.sum()
    assert vz > 0.0
    assert ball.p.x[:, 2].min() > -1e-3
    block = s.parts[1]
    assert (block.kin.m * block.kin.v[:, 2]).sum() < p0[2]
    s = _stepper(contact="")
    while s.t < 80e-6:
        s.step(80e-6)
    assert s.parts[0].p.x[:, 2].min() < -2e-3


@pytest.mark.parametrize("contact, words", [
    ("[mesh.contact]\n[mesh.convert]\nregion = { shape = \"box\", lo = [-1, -1, -1], "
     "hi = [1, 1, \"-10 mm\"] }", "already makes every particle"),
    ("[mesh.contact]\n[mesh.erosion]\nalpha = 0.5", "through [mesh.contact]"),
])
def test_contact_with_a_second_coupling_of_the_particles_is_refused(contact, words):
    with pytest.raises(DeckError, match=words.replace("[", "\\[").replace("]", "\\]")):
        loads_deck(DECK.format(contact=contact, t_end="1 us", steel=STEEL))


def test_the_springs_step_is_chosen_in_the_deck():
    """``stiffness_step`` reaches the coupling (default "current"); a value
    that is not one of the two is refused naming the key."""
    for text, largest in (("[mesh.contact]", False),
                          ('[mesh.contact]\nstiffness_step = "largest"', True)):
        s = _stepper(contact=text)
        cp = next(i for i in s.interactions if isinstance(i, PenaltyCoupling))
        assert cp.largest_step is largest
    with pytest.raises(DeckError, match="stiffness_step"):
        loads_deck(DECK.format(contact='[mesh.contact]\nstiffness_step = "smallest"',
                               t_end="1 us", steel=STEEL))


# --------------------------------------------------- node-to-surface: meshes
MESHES = """
[run]
dimension = 3
t_end = "{t_end}"
{steel}[[mesh]]
name = "cube"
material = "steel"
velocity = [0, 0, "-50 m/s"]
block = {{ lo = ["-5 mm", "-5 mm", "{z0} mm"], hi = ["5 mm", "5 mm", "{z1} mm"], divisions = [2, 2, 2] }}
""" + TARGET

#: the cube's elements are 5 mm: its nodes meet the faces at 0.5 x 5 mm (the
#: default thickness_factor times the node's size), here 1 mm below its start
GAP = 1.0 + 2.5


def _meshes(contact='[mesh.contact]\nmeshes = ["cube"]', t_end="80 us", gap=GAP):
    return build_stepper(loads_deck(MESHES.format(contact=contact, t_end=t_end, steel=STEEL,
                                                  z0=gap, z1=gap + 10.0)))


def test_a_meshed_cube_rebounds_from_the_block_keeping_momentum_and_energy():
    """A 10 mm hex cube at 50 m/s onto the block with ``[mesh.contact] meshes
    = ["cube"]``: the cube's nodes are slaves of the block's faces (one
    coupling, named block_contact_cube; a model without particles has no
    particles' coupling). Momentum is kept to 1e-9 of the initial (round-off over
    ~160 steps: the node's force goes to the face nodes with shape functions
    summing to one). The energy balance E_total after the contact (t > 35
    us): its mean within 1 % of the initial kinetic energy, each record
    within 4 % (the spring stores and returns its energy, 0.1-0.2 % of it
    left in E_contact; the records swing by -2.2 to +3.1 % about the initial
    energy, measured, because the kinetic energy is taken at the last kick
    while the two coarse elastic meshes ring at periods of a few steps:
    -1.9 to +2.7 % before the element step took in the hourglass control's
    terms, whose shorter step, 3-20 % here, stiffens the contact spring
    alpha m / dt^2 and the ringing with it); the cube turns back (its z-velocity > 0), its lowest
    node never more than 0.2 mm behind the thickness (the bottom nodes'
    mass springs, k = alpha m/dt^2 on a quarter of the cube's mass M, stop
    the cube as one body within v dt sqrt(M / (alpha M/4)) = 0.16 mm at
    alpha 0.1, dt 0.5 us).
    Without ``meshes`` the cube passes into the block."""
    s = _meshes()
    names = [i.name for i in s.interactions if isinstance(i, PenaltyCoupling)]
    assert names == ["block_contact_cube"]
    cube = s.parts[0]
    p0 = _momentum(s)
    ke0 = 0.5 * (cube.kin.m * 50.0**2).sum()
    lowest, totals = np.inf, []
    while s.t < 80e-6:
        s.step(80e-6)
        lowest = min(lowest, cube.kin.x[:, 2].min())
        if s.t > 35e-6:
            totals.append(s.record()["E_total"])
    assert np.abs(_momentum(s) - p0).max() < 1e-9 * np.abs(p0).max()
    assert abs(np.mean(totals) - ke0) < 0.01 * ke0
    assert np.abs(np.array(totals) - ke0).max() < 0.04 * ke0
    assert (cube.kin.m * cube.kin.v[:, 2]).sum() > 0.0
    assert lowest > 2.5e-3 - 0.2e-3
    s = _meshes(contact="")
    while s.t < 80e-6:
        s.step(80e-6)
    assert abs(s.parts[0].kin.x[:, 2].min() - (GAP - 4.0) * 1e-3) < 1e-9  # 4 mm in 80 us


def test_the_nodes_meet_the_faces_at_the_thickness():
    """The cube's bottom nodes start 1 mm above the thickness (2.5 mm, half the
    5 mm element size): no contact until they have flown it at 50 m/s
    (20 us), then contact. A wrong size (the node's share of its elements'
    volume, smaller on the cube's edges) or a missing factor moves that
    time by a quarter or more; the steps are 0.5 us."""
    s = _meshes(t_end="40 us")
    cp = next(i for i in s.interactions if i.name == "block_contact_cube")
    first = None
    while s.t < 40e-6 and first is None:
        s.step(40e-6)
        if cp.count:
            first = s.t
    assert first is not None and abs(first - 20e-6) < 1.5e-6


@pytest.mark.parametrize("meshes, words", [
    ('["block"]', "does not contact its own faces"),
    ('["bar"]', "is a line of trusses"),
    ('["nothing"]', "nothing"),
])
def test_contact_meshes_must_be_other_solid_meshes(meshes, words):
    bar = ('[[mesh]]\nname = "bar"\nmaterial = "steel"\nelement = "truss"\n'
           'line = { start = [0, 0, "-10 mm"], end = ["10 mm", 0, "-10 mm"], '
           'element_length = "5 mm" }\nsection = { shape = "circle", diameter = "2 mm" }\n')
    text = MESHES.format(contact=f"[mesh.contact]\nmeshes = {meshes}\n" + bar,
                         t_end="1 us", steel=STEEL, z0=GAP, z1=GAP + 10.0)
    with pytest.raises(DeckError, match=words):
        build_stepper(loads_deck(text))
