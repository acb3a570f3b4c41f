"""Prism bodies: a polygon extruded along an axis (the L-specimen, I-sections)."""

import numpy as np
import pytest

from sphdyn.deck import DeckError, loads_deck
from sphdyn.geometry.lattice import polygon_contains, prism_lattice
from decks import STEEL

# Winkler's L: 500 x 500 mm with a 250 x 250 mm corner cut away
L_POLY = [[0, 0], [0.25, 0], [0.25, 0.25], [0.5, 0.25], [0.5, 0.5], [0, 0.5]]
L_AREA = 0.5 * 0.5 - 0.25 * 0.25


@pytest.mark.parametrize("dx", [0.25 / 15, 0.01, 0.00625])
def test_l_prism_volume_is_exact_on_matching_spacings(dx):
    # vertices on multiples of dx from the bounding box: every cell is wholly
    # in or out, so count * dx^3 = area * length to round-off (1e-9).
    x = prism_lattice(L_POLY, dx, 3, axis="z", base=0.0, length=0.05)
    assert x.shape[0] * dx**3 == pytest.approx(L_AREA * 0.05, rel=1e-9)
    assert x[:, 2].min() > 0 and x[:, 2].max() < 0.05
    cut = (x[:, 0] > 0.25) & (x[:, 1] < 0.25)  # nothing in the cut-out
    assert not cut.any()
    x2 = prism_lattice(L_POLY, dx, 2)
    assert x2.shape[0] * dx**2 == pytest.approx(L_AREA, rel=1e-9)
    assert np.all(x2[:, 2] == 0.0)


def test_prism_axis_maps_the_plane_cyclically():
    # axis x: the polygon is in (y, z); clockwise or counter-clockwise alike
    tri = [[0, 0], [0.1, 0], [0, 0.1]]
    x = prism_lattice(tri, 0.01, 3, axis="x", base=0.2, length=0.03)
    assert np.all((x[:, 0] > 0.2) & (x[:, 0] < 0.23))
    assert np.all(x[:, 1] + x[:, 2] <= 0.1 + 1e-12)
    y = prism_lattice(tri[::-1], 0.01, 3, axis="x", base=0.2, length=0.03)
    assert np.array_equal(x, y)
    z = prism_lattice(tri, 0.01, 3, axis="y", base=0.0, length=0.03)
    assert np.all(z[:, 2] + z[:, 0] <= 0.1 + 1e-12)  # (z, x) plane


def test_polygon_contains_against_a_direct_rule():
    # a concave polygon (the L) against its definition as a box minus a box,
    # on random points; boundary points kept within the tolerance
    rng = np.random.default_rng(0)
    p = rng.uniform(-0.1, 0.6, (5000, 2))
    inside = ((p >= 0) & (p <= 0.5)).all(axis=1) & ~((p[:, 0] > 0.25) & (p[:, 1] < 0.25))
    assert np.array_equal(polygon_contains(np.array(L_POLY, float), p, 0.0), inside)
    edge = np.array([[0.25, 0.1], [0.4, 0.25], [0.0, 0.3]])
    assert polygon_contains(np.array(L_POLY, float), edge, 1e-12).all()


def _deck(geometry: str, dim: int = 3) -> str:
    return f"""
[run]
dimension = {dim}
t_end = "1 us"
{STEEL}[[body]]
name = "L"
material = "steel"
dx = "10 mm"
geometry = {geometry}
"""


def test_prism_deck_builds_the_l():
    deck = loads_deck(_deck('{ shape = "prism", points = [[0, 0], ["250 mm", 0], '
                            '["250 mm", "250 mm"], ["500 mm", "250 mm"], '
                            '["500 mm", "500 mm"], [0, "500 mm"]], length = "50 mm" }'))
    g = deck.body[0].geometry
    assert g.shape == "prism" and g.length == pytest.approx(0.05)
    assert g.points[3] == (pytest.approx(0.5), pytest.approx(0.25))


@pytest.mark.parametrize("geometry, dim, words", [
    ('{ shape = "prism", points = [[0, 0], [1, 0]], length = 1 }', 3, "at least 3"),
    ('{ shape = "prism", points = [[0, 0], [1, 0], [2, 0]], length = 1 }', 3, "zero area"),
    ('{ shape = "prism", points = [[0, 0], [2, 2], [2, 0], [0, 1]], length = 1 }', 3,
     "crosses itself"),
    ('{ shape = "prism", points = [[0, 0], [1, 0], [0, 1]] }', 3, "needs a length"),
    ('{ shape = "prism", points = [[0, 0], [1, 0], [0, 1]], length = 1 }', 2,
     "means nothing in a 2D deck"),
    ('{ shape = "prism", points = [[0, 0], [1, 0], [0, 1]], axis = "x" }', 2,
     "not allowed in 2D"),
])
def test_bad_prisms_are_refused_naming_the_field(geometry, dim, words):
    with pytest.raises(DeckError) as err:
        loads_deck(_deck(geometry, dim))
    assert words in str(err.value) and "geometry" in str(err.value)


# an I-section 120 x 200 mm: flanges 40 mm thick, web 40 mm
I_POLY = [[0, 0], [0.12, 0], [0.12, 0.04], [0.08, 0.04], [0.08, 0.16], [0.12, 0.16],
          [0.12, 0.2], [0, 0.2], [0, 0.16], [0.04, 0.16], [0.04, 0.04], [0, 0.04]]
I_AREA = 2 * 0.12 * 0.04 + 0.04 * 0.12


def test_prism_mesh_fills_the_i_and_its_centres_are_the_prism_particles():
    """[mesh.prism] = the elements whose centres are the particles of the
    prism body at dx = element size (same geometry for an SPH model and its
    FEM reference): the same points to 1e-12 m, the volume exact (1e-9; the
    vertices sit on the grid), every element right-handed, no unused node,
    the end-face node sets on the extrusion's ends."""
    from sphdyn.geometry.mesh import check_elements, element_jacobians
    from sphdyn.geometry.mesh_blocks import prism_mesh
    m = prism_mesh(I_POLY, 0.02, 3, axis="x", base=0.1, length=0.4)
    check_elements(m)
    det = element_jacobians(m.points, m.cells, m.kind)
    assert det.min() > 0
    assert np.sum(det.mean(axis=1) * 8) == pytest.approx(I_AREA * 0.4, rel=1e-9)
    assert np.array_equal(np.unique(m.cells), np.arange(m.n_nodes))
    centres = m.points[m.cells].mean(axis=1)
    x = prism_lattice(I_POLY, 0.02, 3, axis="x", base=0.1, length=0.4)
    order = lambda a: a[np.lexsort(np.round(a, 9).T)]  # noqa: E731
    assert np.allclose(order(centres), order(x), rtol=0, atol=1e-12)
    assert np.allclose(m.points[m.node_sets["xmin"], 0], 0.1)
    assert np.allclose(m.points[m.node_sets["xmax"], 0], 0.5)
    # per section: (6 + 1 + ... ) nodes; the web's grid lines are shared
    assert m.node_sets["xmin"].size == m.n_nodes // 21
    # 2D: the polygon itself as quads
    q = prism_mesh(L_POLY, 0.05, 2)
    assert q.kind == "quad4" and q.n_elements * 0.05**2 == pytest.approx(L_AREA, rel=1e-9)
    assert np.all(q.points[:, 2] == 0.0)


def test_prism_mesh_deck_and_its_errors():
    """A [mesh.prism] deck builds the I; a 2D prism with a length and a mesh
    with two sources are refused naming the field."""
    from sphdyn.build.model import build_model
    pts = ('[[0, 0], ["120 mm", 0], ["120 mm", "40 mm"], ["80 mm", "40 mm"], '
           '["80 mm", "160 mm"], ["120 mm", "160 mm"], ["120 mm", "200 mm"], [0, "200 mm"], '
           '[0, "160 mm"], ["40 mm", "160 mm"], ["40 mm", "40 mm"], [0, "40 mm"]]')

    def deck(prism, dim=3, extra=""):
        return f"""
[run]
dimension = {dim}
t_end = "1 us"
{STEEL}[[mesh]]
name = "girder"
material = "steel"
prism = {prism}
{extra}
"""
    d = loads_deck(deck(f'{{ points = {pts}, axis = "x", length = "400 mm", '
                        'element_size = "20 mm" }'))
    model = build_model(d)
    mm = model.meshes[0]
    assert mm.cells.shape[0] == round(I_AREA * 0.4 / 0.02**3)
    with pytest.raises(DeckError, match=r"mesh\[0\]\.prism\.length: .*means nothing in a 2D deck"):
        loads_deck(deck(f'{{ points = {pts}, length = "400 mm", element_size = "20 mm" }}',
                        dim=2))
    with pytest.raises(DeckError, match="exactly one source"):
        loads_deck(deck(f'{{ points = {pts}, axis = "x", length = "400 mm", '
                        'element_size = "20 mm" }',
                        extra='block = { lo = [0, 0, 0], hi = [1, 1, 1], '
                              'divisions = [1, 1, 1] }'))
