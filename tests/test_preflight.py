"""The size estimate made before a model is built (sphdyn.preflight)."""

import math
from pathlib import Path

import pytest

from sphdyn.deck import load_deck
from sphdyn.model import build_model
from sphdyn.neighbours import max_neighbours
from sphdyn.preflight import estimate_size, history_width, lattice_neighbours, shape_volume
from sphdyn.simulation import Simulation

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


class _Shape:
    def __init__(self, **kw):
        self.__dict__.update(kw)


@pytest.mark.parametrize("shape, dim, volume", [
    (_Shape(shape="box", lo=(0, 0, 0), hi=(0.2, 0.1, 0.05)), 3, 0.2 * 0.1 * 0.05),
    (_Shape(shape="box", lo=(0, 0, 0), hi=(0.2, 0.1, 0.0)), 2, 0.2 * 0.1),
    (_Shape(shape="sphere", radius=0.1), 3, 4 / 3 * math.pi * 0.1 ** 3),
    (_Shape(shape="sphere", radius=0.1), 2, math.pi * 0.1 ** 2),
    (_Shape(shape="cylinder", radius=0.05, length=0.3), 3, math.pi * 0.05 ** 2 * 0.3),
    (_Shape(shape="ring", inner_radius=0.03, outer_radius=0.04, length=None), 2,
     math.pi * (0.04 ** 2 - 0.03 ** 2)),
    (_Shape(shape="prism", points=((0, 0), (0.25, 0), (0.25, 0.25), (0.5, 0.25),
                                   (0.5, 0.5), (0, 0.5)), length=0.05), 3,
     (0.25 - 0.0625) * 0.05),
    (_Shape(shape="prism", points=((0, 0), (0, 0.1), (0.3, 0)), length=None), 2, 0.015),
])
def test_shape_volumes_are_the_closed_forms(shape, dim, volume):
    assert shape_volume(shape, dim) == pytest.approx(volume, rel=1e-14)


@pytest.mark.parametrize("deck", ["disc_impact", "rings_gray2001", "two_boxes",
                                  "ucs_cylinder"])
def test_particle_count_estimate_matches_the_lattice(deck):
    # volume / dx^dim against the lattice actually built: the lattice's edge
    # rows make the difference, 3.3 % for the 3D cylinder of 6656 particles
    # (largest of the examples), under 1 % for the others; 4 % allowed
    d = load_deck(EXAMPLES / f"{deck}.toml")
    est = estimate_size(d)
    p = build_model(d).particles
    for b, body in enumerate(d.body):
        n = int((p.body == b).sum())
        assert est.bodies[body.name] == pytest.approx(n, rel=0.04), body.name
    assert est.particles == pytest.approx(sum(est.bodies.values()))


@pytest.mark.parametrize("deck", ["disc_impact", "rings_gray2001", "two_boxes"])
def test_neighbour_estimate_is_an_interior_particles_list(tmp_path, deck):
    # pairs per particle = lattice points in the Verlet ball, counted: an
    # interior particle's list (the longest) at the build holds exactly that
    # many (80 in 3D, 36 and 20 in 2D with the default skin; the ball's
    # volume is 77, 34.2 and 21.9: 4-10 % off at these radii)
    d = load_deck(EXAMPLES / f"{deck}.toml")
    sim = Simulation.from_deck(d, tmp_path / "o")
    longest = max_neighbours(sim.stepper.part("sph").nl)
    assert estimate_size(d).pairs_per_particle == longest


@pytest.mark.parametrize("radius, dim, count", [(1.5, 1, 2), (1.0, 2, 0), (1.01, 2, 4),
                                                (1.5, 2, 8), (1.01, 3, 6), (1.5, 3, 18),
                                                (1.8, 3, 26)])
def test_lattice_neighbours_counts_the_points_strictly_inside(radius, dim, count):
    # by hand: 1D the two nearest; 2D the 4 edge neighbours (at 1, excluded
    # at radius 1 exactly), then the 4 diagonals (sqrt 2); 3D 6 faces, 12
    # edges (sqrt 2), 8 corners (sqrt 3 = 1.73)
    assert lattice_neighbours(radius, dim) == count


@pytest.mark.parametrize("deck", ["igirder_sph", "disc_impact", "rings_gray2001"])
def test_history_width_is_the_built_parts_layout(deck):
    # CSCM concrete beside J2 sublayer particles (igirder_sph) lay their
    # columns side by side: the estimate counts the joined layout, as built
    d = load_deck(EXAMPLES / f"{deck}.toml")
    from sphdyn.assembly import build_stepper

    part = build_stepper(d).part("sph")
    assert history_width(d) == part.p.hist.shape[1]
