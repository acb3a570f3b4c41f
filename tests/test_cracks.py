"""Initial cracks as zero-mass particles (paper sec. 5.2)."""

import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.geometry import lattice_from_shape
from sphdyn.heterogeneity.cracks import crack_mask, crack_particles, distance_to_polyline
from sphdyn.build.model import build_model
from sphdyn.simulation import Simulation

from decks import concrete_disc_2d

DX = 1e-3
BOX = {"shape": "box", "lo": (-0.04, -0.01, 0.0), "hi": (0.04, 0.01, 0.0)}

# A 2D concrete bar 80 mm x 20 mm (dx = 1 mm) pulled at both ends at
# 0.3 m/s: each end sends a tensile wave of about 2.6 MPa, below the CSCM
# tensile strength of 3.1 MPa (docs/cscm.md), which only the two waves
# meeting at the centre exceed (after L / 2c = 11 us). A half-depth crack at
# x = -19.5 mm is reached by the left wave after ~6 us.
BAR = """
[run]
dimension = 2
t_end = "30 us"
[sph.smoothing_length]
mode = "benz"
[[material]]
name = "concrete"
model = "cscm"
density = 2400.0
fc = "43.1 MPa"
aggregate_size = "8 mm"
[[body]]
name = "bar"
material = "concrete"
dx = "1 mm"
geometry = { shape = "box", lo = ["-40 mm", "-10 mm"], hi = ["40 mm", "10 mm"] }
CRACK
[[set]]
name = "left"
region = { shape = "halfspace", point = ["-38 mm", 0], normal = [-1, 0] }
[[set]]
name = "right"
region = { shape = "halfspace", point = ["38 mm", 0], normal = [1, 0] }
[[boundary]]
set = "left"
type = "velocity"
velocity = [-0.3, 0]
[[boundary]]
set = "right"
type = "velocity"
velocity = [0.3, 0]
[output]
every = "10 us"
progress = false
vtk = false
fields = ["damage", "mass"]
"""
NOTCH = """[[body.crack]]
shape = "polyline"
points = [["-19.5 mm", "10 mm", 0], ["-19.5 mm", "0 mm", 0]]
"""


def _lattice():
    return lattice_from_shape(BOX, DX, 2)


def test_polyline_distance_is_the_segment_distance():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    p = np.array([[0.5, 0.3], [-1.0, 0.0], [2.0, 0.5], [1.0, 2.0]])
    assert np.allclose(distance_to_polyline(p, pts), [0.3, 1.0, 1.0, 1.0])


def test_crack_shapes_select_the_expected_rows():
    x = _lattice()  # points at -39.5, ..., 39.5 mm in x; -9.5, ..., 9.5 mm in y
    # a plane through a column of particles: rows = 1 selects that column (20
    # particles), rows = 3 three columns
    col = {"shape": "plane", "point": (0.0005, 0, 0), "normal": (1, 0, 0), "rows": 1}
    assert crack_particles(x, col, DX).sum() == 20
    assert crack_particles(x, dict(col, rows=3), DX).sum() == 60
    # midway between two columns rows = 1 selects nothing (a lattice tie) and
    # crack_mask says so; rows = 2 selects both columns
    mid = dict(col, point=(0.0, 0, 0))
    assert crack_particles(x, mid, DX).sum() == 0
    with pytest.raises(ValueError, match="selects no particle"):
        crack_mask(x, [mid], DX, "bar")
    assert crack_particles(x, dict(mid, rows=2), DX).sum() == 40
    # radius limits the plane crack: |y| <= 5 mm -> y = +-0.5 ... +-4.5 mm
    assert crack_particles(x, dict(col, radius=0.005), DX).sum() == 10
    # polyline from the top edge to the centre line: y = 0.5 ... 9.5 mm
    notch = {"shape": "polyline", "points": [(-0.0195, 0.01, 0), (-0.0195, 0.0, 0)],
             "rows": 1, "axis": "z"}
    sel = crack_particles(x, notch, DX)
    assert sel.sum() == 10 and np.allclose(x[sel, 0], -0.0195)
    # box: 3 x 4 particles
    box = {"shape": "box", "lo": (0.0, 0.0, -1.0), "hi": (0.003, 0.004, 1.0)}
    assert crack_particles(x, box, DX).sum() == 12


def test_crack_particles_get_zero_mass_the_rest_keep_theirs():
    deck = loads_deck(BAR.replace("CRACK", NOTCH))
    p = build_model(deck).particles
    m0 = 2400.0 * DX ** 2
    zero = p.m == 0.0
    assert zero.sum() == 10 and np.allclose(p.x0[zero, 0], -0.0195)
    assert np.all(p.m[~zero] == m0)
    assert np.all(p.rho == 2400.0)  # density and volume vol0 unchanged
    assert np.all(p.vol0 == DX ** 2)
    # with a random mass field the crack is void: the rest carries exactly
    # the homogeneous mass of the non-crack particles (to round-off)
    rnd = BAR.replace("CRACK", 'mass = { distribution = "uniform", low = 0.0, high = 2.0 }\n'
                      + NOTCH)
    q = build_model(loads_deck(rnd)).particles
    assert np.all(q.m[zero] == 0.0)
    assert abs(q.m.sum() - (p.n - 10) * m0) < 1e-12 * p.n * m0


def _run_bar(tmp_path, name, crack):
    """Run the bar; return (onset time, onset position, final state)."""
    sim = Simulation.from_deck(loads_deck(BAR.replace("CRACK", crack)), tmp_path / name)
    s, p = sim.stepper, sim.particles
    onset = None
    while s.t < sim.deck.run.t_end * (1 - 1e-12):
        s.step()
        # failure onset among particles that carry mass: damage > 0.05
        d = np.where(p.m > 0, p.damage, 0.0)
        if onset is None and d.max() > 0.05:
            k = int(np.argmax(d))
            onset = (s.t, p.x0[k].copy())
    return onset, p


def test_a_crack_weakens_the_body_and_failure_starts_at_its_tip(tmp_path):
    # Intact bar: damage starts where the two waves meet (near x = 0) after
    # about 25 us. Notched bar: at the crack tip (-19.5 mm, 0) after ~16 us,
    # i.e. earlier and within 1.5 particle spacings of the tip; the final
    # damage near the notch exceeds anything in the intact bar. The run with
    # zero-mass particles stays finite to the end.
    (t_i, x_i), p_i = _run_bar(tmp_path, "intact", "")
    (t_c, x_c), p_c = _run_bar(tmp_path, "notched", NOTCH)
    assert abs(x_i[0]) < 3 * DX
    assert np.hypot(x_c[0] + 0.0195, x_c[1]) < 1.5 * DX
    assert t_c < 0.8 * t_i
    near = np.hypot(p_c.x0[:, 0] + 0.0195, p_c.x0[:, 1]) < 3 * DX
    assert p_c.damage[near & (p_c.m > 0)].max() > 1.5 * p_i.damage.max()  # 0.16 vs 0.08
    for arr in (p_c.x, p_c.v, p_c.sig, p_c.rho, p_c.h, p_c.damage):
        assert np.all(np.isfinite(arr))


@pytest.mark.parametrize("stiffness", ["bulk", "mass"])
def test_disc_with_crack_and_pore_block_is_stable_to_the_end(tmp_path, stiffness):
    # The paper's disc (2D, CSCM) with a vertical through-crack and a 3 x 3
    # block of zero-mass particles whose centre particle has only massless
    # neighbours within one spacing, hitting the base where zero-mass
    # particles touch it first. No NaN, no division by zero; the zero-mass
    # particles move with the disc (interpolation points), with both wall
    # stiffness laws (bulk = paper eq. 9; mass = eq. 8, whose m -> 0 limit is
    # an acceleration).
    cracks = """
[[body.crack]]
shape = "polyline"
points = [["1.25 mm", 0, 0], ["1.25 mm", "60 mm", 0]]
[[body.crack]]
shape = "box"
lo = ["-30 mm", "45 mm", 0]
hi = ["-23 mm", "52 mm", 0]
"""
    text = concrete_disc_2d("2.5 mm", "60 us", "20 us", ["damage", "mass", "velocity"],
                            body=cracks, stiffness=stiffness)
    sim = Simulation.from_deck(loads_deck(text), tmp_path / stiffness)
    p = sim.particles
    zero = p.m == 0
    assert zero.sum() > 20
    summary = sim.run()
    assert summary["status"] == "completed"
    for arr in (p.x, p.v, p.a, p.sig, p.rho, p.h, p.e, p.damage):
        assert np.all(np.isfinite(arr))
    # the zero-mass particles move with the material around them: their
    # displacement differs from the mean of the massive particles within one
    # kernel support (2.4 dx, reference configuration) by less than a tenth
    # of the spacing (0.25 mm; the disc moves ~0.8 mm; measured up to
    # 0.17 mm near the contact zone, where the velocity gradient is large).
    # Zero-mass particles touching the wall (y0 < dx) are held by it.
    from scipy.spatial import cKDTree

    disp = p.x - p.x0
    tree = cKDTree(p.x0[~zero])
    for i in np.flatnonzero(zero & (p.x0[:, 1] > 2.5e-3)):
        nb = tree.query_ball_point(p.x0[i], 2.4 * 2.5e-3)
        mean = disp[~zero][nb].mean(axis=0)
        assert np.linalg.norm(disp[i] - mean) < 0.1 * 2.5e-3, i
    assert p.x[zero, 1].min() > -1e-3  # none went through the wall
    assert summary["peak_F_wall_base"] > 0
