"""[mesh.contact]: the particles of every body meet a mesh's faces by penalty.

The coupling itself (spring, shape-function split, friction, momentum,
energy) is verified in tests/test_penalty_coupling.py; here the deck makes
it: an SPH projectile strikes a free hex block and rebounds, the pair
keeping its momentum to round-off and the block taking the impulse.
"""

import numpy as np
import pytest

from sphdyn.assembly import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.interactions.penalty_coupling import PenaltyCoupling

from decks import STEEL

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
[[mesh]]
name = "block"
material = "steel"
block = {{ lo = ["-20 mm", "-20 mm", "-20 mm"], hi = ["20 mm", "20 mm", 0], divisions = [8, 8, 4] }}
{contact}
[output]
every = "{t_end}"
progress = false
vtk = false
"""


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
