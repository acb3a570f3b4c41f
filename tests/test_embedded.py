"""Bars embedded in solid elements (LS-DYNA's CONSTRAINED_BEAM_IN_SOLID): the
pure FEM reference of reinforced concrete (thesis 6.1).

Pinned: the parametric search finds the element and point of random points
in a distorted mesh (x(xi) = p to 1e-12) and none outside; a bar embedded
along a block pulled slowly carries its share: the end reaction is
(E_c A_c + E_s A_s) eps within 0.1 % (perfect bond, the bar's volume counted
twice as in LS-DYNA; measured -0.005 % with and without the bar, the rest of
the margin for the ringing the damped ramp leaves), the block's nodes carry
the bar's mass (1e-12); bad input is named.
"""

from __future__ import annotations

import numpy as np
import pytest

from fem_models import block
from sphdyn.deck import DeckError, loads_deck
from sphdyn.build import build_stepper
from sphdyn.geometry.shapes import shape_functions
from sphdyn.interactions.embedded import locate
from sphdyn.io import read_history_csv
from sphdyn.simulation import Simulation
from decks import STEEL

COMPOSITE = """
[run]
dimension = 3
t_end = "1.5 ms"
[[material]]
name = "concrete"
model = "elastic"
density = 2400.0
E = "30 GPa"
nu = 0.0
""" + STEEL + """[[mesh]]
name = "block"
material = "concrete"
damping = "20000 1/s"
block = { lo = [0, 0, 0], hi = ["200 mm", "40 mm", "40 mm"], divisions = [20, 4, 4] }
{bar}
[[set]]
name = "left"
mesh = "block"
region = { shape = "box", lo = [-1, -1, -1], hi = ["0.1 mm", 1, 1] }
[[set]]
name = "right"
mesh = "block"
region = { shape = "box", lo = ["199.9 mm", -1, -1], hi = [1, 1, 1] }
[[boundary]]
set = "left"
type = "fixed"
[[boundary]]
set = "right"
type = "displacement"
displacement = ["0.02 mm", 0, 0]
ramp_time = "1 ms"
ramp = "smooth"
[output]
every = "1.5 ms"
history_every = 10
progress = false
vtk = false
"""
BAR = """
[[mesh]]
name = "bar"
material = "steel"
element = "truss"
line = { start = [0, "20 mm", "20 mm"], end = ["200 mm", "20 mm", "20 mm"], element_length = "10 mm" }
section = { shape = "circle", diameter = "10 mm" }
embed = "block"
"""


def test_points_are_found_in_a_distorted_mesh():
    rng = np.random.default_rng(1)
    x, cells = block([0, 0, 0], [1, 1, 1], (3, 3, 3), 3)
    inner = np.all((x > 1e-9) & (x < 1 - 1e-9), axis=1)
    x[inner] += rng.uniform(-0.05, 0.05, (inner.sum(), 3))
    e_true = rng.integers(0, cells.shape[0], 20)
    xi_true = rng.uniform(-0.9, 0.9, (20, 3))
    pts = np.array([shape_functions(3, s)[0] @ x[cells[e]] for e, s in zip(e_true, xi_true)])
    elem, xi = locate(pts, x, cells, 3)
    assert np.all(elem >= 0)
    back = np.array([shape_functions(3, s)[0] @ x[cells[e]] for e, s in zip(elem, xi)])
    assert np.abs(back - pts).max() < 1e-12
    elem, _ = locate(np.array([[1.5, 0.5, 0.5]]), x, cells, 3)
    assert elem[0] == -1


@pytest.mark.parametrize("with_bar", [False, True])
def test_embedded_bar_adds_its_axial_stiffness(tmp_path, with_bar):
    text = COMPOSITE.replace("{bar}", BAR if with_bar else "")
    sim = Simulation.from_deck(loads_deck(text), tmp_path / "run")
    block_m = 2400.0 * 0.2 * 0.04 * 0.04
    bar_m = 7850.0 * np.pi * 0.005 ** 2 * 0.2
    assert sim.stepper.part("block").nodes.m.sum() == pytest.approx(
        block_m + (bar_m if with_bar else 0.0), rel=1e-12)
    sim.run()
    h = read_history_csv(tmp_path / "run/history.csv")
    eps = 0.02e-3 / 0.2
    stiffness = 30e9 * 0.04 * 0.04 + (200e9 * np.pi * 0.005 ** 2 if with_bar else 0.0)
    assert h["right_reaction_x"][-1] == pytest.approx(stiffness * eps, rel=1e-3)


def test_a_bar_outside_its_solid_is_refused():
    text = COMPOSITE.replace("{bar}", BAR.replace('end = ["200 mm", "20 mm", "20 mm"]',
                                                  'end = ["300 mm", "20 mm", "20 mm"]'))
    with pytest.raises(DeckError, match="lie in no element"):
        build_stepper(loads_deck(text))


def test_embedding_in_a_line_mesh_or_with_a_sublayer_is_refused():
    bars = BAR + BAR.replace('name = "bar"', 'name = "bar2"').replace(
        'embed = "block"', 'embed = "bar"')
    with pytest.raises(DeckError, match="not solid elements"):
        build_stepper(loads_deck(COMPOSITE.replace("{bar}", bars)))
    with pytest.raises(DeckError, match="either in SPH concrete"):
        loads_deck(COMPOSITE.replace("{bar}", BAR + "[mesh.sublayer]\nmass_ratio = 0.5\n"))
