"""The energy a tension crack dissipates per unit area: G_F, in SPH and in a mesh.

A softening material spreads its fracture energy G_F over a length L,
G_F = L * (area under the post-peak stress-strain curve) (crack band; CSCM:
docs/cscm.md, the regularisation of its softening, pinned at the material
point by tests/test_cscm.py). Whether a whole crack then dissipates G_F per
unit area depends on how many rows of points it softens: a mesh's crack
takes one element row (L = the element size); an SPH crack opens between two
rows of particles and softens both, so L = dx dissipates twice G_F and
[sph] crack_band = 2 (L = 2 dx) gives G_F (the default, 1, keeps the paper's
and thesis's particle size).

The check: a concrete bar (CSCM, f'c 40 MPa, 16 mm aggregate: G_FT = 79.2
J/m^2) held at one end and pulled at 0.2 m/s at the other until it has
broken through. Its crack is the points with damage > 0.9; the energy they
dissipated is the sum of their m e (internal energy; the elastic part left
in them is nil once the stress is gone). Per ligament area and G_FT, measured:
a 2D SPH bar 1.11 with crack_band = 2 and 2.11 with 1 (two particle layers
either way, at dx 2.5 and 1.25 mm alike); a 3D mesh of 2.5 mm hexahedra 1.05
(one element row). Tolerances: [0.95, 1.25] for G_F (the points' pre-peak
work and the tail of the softening, d < 1, add 5-11 %); the ratio of the
two bands 1.7-2.1 (post-peak energy is proportional to 1 / L, the pre-peak
part is not).
"""

from __future__ import annotations

from sphdyn.build import build_stepper
from sphdyn.deck import loads_deck

GFT = 79.17047464637365  # J/m^2, the CSCM fit for f'c 40 MPa, 16 mm aggregate

COMMON = """
[run]
dimension = {dim}
t_end = "{t_end}"

[sph]
h_factor = 1.2
crack_band = {band}

[[material]]
name = "concrete"
model = "cscm"
density = "2300 kg/m^3"
fc = "40 MPa"
aggregate_size = "16 mm"

{body}

[[set]]
name = "left"
{owner}
region = {{ shape = "box", lo = [-1, -1, -1], hi = ["5.1 mm", 1, 1] }}

[[set]]
name = "right"
{owner}
region = {{ shape = "box", lo = ["94.9 mm", -1, -1], hi = [1, 1, 1] }}

[[boundary]]
set = "left"
type = "fixed"

[[boundary]]
set = "right"
type = "velocity"
velocity = ["0.2 m/s", 0, 0]
ramp_time = "0.05 ms"
components = ["x"]

[output]
progress = false
vtk = false
"""

SPH_BAR = """[[body]]
name = "bar"
material = "concrete"
dx = "2.5 mm"
geometry = { shape = "box", lo = [0, 0], hi = ["100 mm", "20 mm"] }"""

MESH_BAR = """[[mesh]]
name = "bar"
material = "concrete"
block = { lo = [0, 0, 0], hi = ["100 mm", "20 mm", "20 mm"], divisions = [40, 8, 8] }"""


def _crack(deck_text):
    """Run the bar; the points with damage > 0.9 and the energy they hold [J]."""
    s = build_stepper(loads_deck(deck_text))
    t_end = 2e-3
    while s.t < t_end:
        s.step(t_stop=t_end)
    part = s.parts[0]
    pts = part.pts if hasattr(part, "pts") else part.p
    crack = pts.damage > 0.9
    return int(crack.sum()), float(pts.m[crack] @ pts.e[crack])


def test_an_sph_crack_dissipates_the_fracture_energy_over_two_particle_layers():
    area = 0.020  # the ligament, m^2 per m of thickness (2D)
    rows = 8  # particles across the 20 mm bar
    ratio = {}
    for band in (2.0, 1.0):
        n, energy = _crack(COMMON.format(dim=2, t_end="2 ms", band=band, body=SPH_BAR,
                                            owner='body = "bar"'))
        assert n == 2 * rows  # broken through, two layers
        ratio[band] = energy / (GFT * area)
    assert 0.95 < ratio[2.0] < 1.25
    assert 1.7 < ratio[1.0] / ratio[2.0] < 2.1


def test_a_mesh_crack_dissipates_the_fracture_energy_in_one_element_row():
    n, energy = _crack(COMMON.format(dim=3, t_end="2 ms", band=2.0, body=MESH_BAR,
                                        owner='mesh = "bar"'))
    assert n == 8 * 8 * 1  # one row of the 8 x 8 section's one-point elements
    assert 0.95 < energy / (GFT * 0.020 * 0.020) < 1.25
