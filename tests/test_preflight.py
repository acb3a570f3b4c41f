"""The size estimate made before a model is built (sphdyn.checks.size)."""

import math
from pathlib import Path

import pytest

from sphdyn.deck import load_deck
from sphdyn.build.model import build_model
from sphdyn.neighbours import max_neighbours
from sphdyn.checks.size import estimate_size, history_width, lattice_neighbours, shape_volume
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
    from sphdyn.build import build_stepper

    part = build_stepper(d).part("sph")
    assert history_width(d) == part.p.hist.shape[1]


def _mutated(tmp_path, deck: str, path: tuple, value) -> str:
    """``examples/<deck>.toml`` with the key at ``path`` set to ``value``."""
    import tomllib

    import tomli_w

    with open(EXAMPLES / f"{deck}.toml", "rb") as f:
        doc = tomllib.load(f)
    node = doc
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    out = tmp_path / f"{deck}.toml"
    out.write_text(tomli_w.dumps(doc))
    return str(out)


@pytest.mark.parametrize("deck, path, value, field", [
    ("elastic_disc_bounce", ("sph", "h_factor"), 1e6, "sph.h_factor"),
    ("disc_impact", ("sph", "support_scale"), 1e6, "sph.support_scale"),
    ("sod_shock_tube", ("sph", "neighbours"), {"skin_factor": 1e9}, "sph.neighbours.skin_factor"),
    ("elastic_disc_bounce", ("sph", "h_factor"), 1e300, "sph.h_factor"),
    ("disc_impact", ("sph", "support_scale"), 1e-9, "sph.support_scale"),
    ("beam_fem", ("mesh", 0, "block", "divisions"), [1_000_000_000, 8, 8],
     "mesh[0].block.divisions"),
    ("beam_hybrid", ("mesh", 0, "block", "divisions"), [1_000_000, 80, 80],
     "mesh[0].block.divisions"),
    ("blast_slab_coarse", ("mesh", 0, "line", "element_length"), "1e-9 m",
     "mesh[0].line.element_length"),
    ("igirder_fem", ("mesh", 0, "prism", "element_size"), "1e-9 m",
     "mesh[0].prism.element_size"),
    ("disc_impact", ("body", 0, "dx"), "1e-9 m", "body[0].dx"),
])
def test_absurd_sizes_are_refused_before_anything_large_is_allocated(
        tmp_path, capsys, deck, path, value, field):
    """`sphdyn check` of a deck whose numbers ask for an absurd model exits 2
    naming the key and a fix, allocating little on the way: a smoothing-length
    factor of 1e6 made the neighbour count allocate 141 TiB
    (numpy ArrayMemoryError); a mesh's element count had no bound before its
    particles were counted; a support_scale of 1e-9 (no neighbour at all)
    passed. The peak of Python allocations (tracemalloc,
    which sees NumPy's buffers) stays below 100 MB, far below any of these
    models and above the examples' own meshes (beam: 10,240 hexes)."""
    import tracemalloc

    from sphdyn.cli import main

    deck_path = _mutated(tmp_path, deck, path, value)
    tracemalloc.start()
    try:
        rc = main(["check", deck_path])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.count("\n") <= 2 and field in err and "Fix:" in err, err
    assert peak < 100e6


@pytest.mark.parametrize("radius, dim", [(40.5, 3), (1e6, 2), (1e6, 1)])
def test_lattice_neighbours_beyond_the_enumerated_radius_is_the_ball(radius, dim):
    """Past 40 spacings the count is the ball's volume minus one (no point
    grid); at 40.5 dx in 3D it is within 1 % of the enumerated count at
    40 dx scaled by the volume ratio (the surface points' share there is
    3/40 at most; 1 % is what the two radii's counts differ by beyond the
    volume ratio). An overflowing radius gives inf."""
    from sphdyn.checks.size import ball_volume

    got = lattice_neighbours(radius, dim)
    assert got == ball_volume(radius, dim) - 1.0
    if dim == 3:
        near = lattice_neighbours(40.0, 3) * (radius / 40.0) ** 3
        assert got == pytest.approx(near, rel=0.01)
    assert lattice_neighbours(1e300, 3) == math.inf


def test_check_counts_the_particles_of_converted_and_eroding_elements(capsys):
    """Particles made from elements count: beam_hybrid's converted region
    (64 x 8 x 8 = 4096 elements) and its hybrid layer (2 x 64 one-point
    elements) make 4224 particles, which the estimate before the build
    counts exactly on the generated mesh and `check` reports (it said
    "about 0 particles"); erosion into particles may add one per element
    of erosion_blocks_sph (1000), which check says."""
    from sphdyn.cli import main

    d = load_deck(EXAMPLES / "beam_hybrid.toml")
    est = estimate_size(d)
    assert est.bodies == {"beam": 4224.0} and est.particles == 4224.0
    assert est.pairs_per_particle == 80
    assert main(["check", str(EXAMPLES / "beam_hybrid.toml")]) == 0
    assert "estimate: about 4,224 particles, 80 neighbours" in capsys.readouterr().out
    d = load_deck(EXAMPLES / "erosion_blocks_sph.toml")
    est = estimate_size(d)
    assert est.debris == {"block_debris": 1000.0} and est.particles == 1000.0
    assert main(["check", str(EXAMPLES / "erosion_blocks_sph.toml")]) == 0
    assert ("about 0 particles (+ up to 1,000 from eroding elements)"
            in capsys.readouterr().out)
