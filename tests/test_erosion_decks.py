"""Element erosion from decks: [material.erosion] and [mesh.erosion].

What is pinned here: a cube of elements with erosion into particles, from a
deck with no [[body]], makes its debris body and coupling, keeps its mass to
round-off, writes the erosion columns and the born particles into the
frames, and restarts bitwise across conversions; plain erosion reports the
mass it lost; bad input (the damage rule on a model without damage, an
eroding mesh whose materials have no rules, a rule table with no rule,
erosion into particles with a tied coupling, keys of
particles with to = "nothing") is refused naming the field, exit 2, nothing
written.
"""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.deck import loads_deck
from sphdyn.io import read_checkpoint, read_history_csv
from sphdyn.io.hdf5 import read_frame
from sphdyn.simulation import Simulation
from test_mesh_decks import _bad

CUBE = """
[run]
dimension = 3
t_end = "{t_end}"
[[material]]
name = "concrete"
model = "elastic"
density = 2400.0
E = 30e9
nu = 0.2
{rules}
[[mesh]]
name = "cube"
material = "concrete"
block = {{lo = [0, 0, 0.0055], hi = [0.04, 0.04, 0.0455], divisions = [4, 4, 4]}}
velocity = [0, 0, "-20 m/s"]
{erosion}
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 0, 1]
[output]
progress = false
vtk = false
history_every = 5
every = "{every}"
{extra}
"""
RULES = "[material.erosion]\neffective_strain = 0.002"
TO_PARTICLES = '[mesh.erosion]\nto = "particles"'


def cube(t_end="0.3 ms", every="0.1 ms", rules=RULES, erosion=TO_PARTICLES, extra=""):
    return CUBE.format(t_end=t_end, every=every, rules=rules, erosion=erosion, extra=extra)


def test_eroding_cube_from_a_deck_makes_debris_and_keeps_its_mass(tmp_path):
    sim = Simulation.from_deck(loads_deck(cube()), tmp_path / "run")
    s = sim.stepper
    assert [p.name for p in s.parts] == ["sph", "cube"]
    assert "cube_debris" in [i.name for i in s.interactions]
    m0 = s.part("cube").nodes.m.sum()
    sim.run()
    sph = s.part("sph")
    n = sph.p.n
    assert n > 0
    assert np.all(sph.p.body == 0)  # the debris body, the only one
    assert s.part("cube").nodes.m.sum() + sph.p.m.sum() == pytest.approx(m0, rel=1e-12)
    h = read_history_csv(tmp_path / "run/history.csv")
    assert h["eroded_cube"][-1] == n
    assert h["particles_from_cube"][-1] == n
    assert h["eroded_cube_effective_strain"][-1] == n
    frames = sorted((tmp_path / "run/frames").glob("*.h5"))
    assert read_frame(frames[0])[2]["position"].shape[0] == 0  # t = 0: no particle yet
    assert read_frame(frames[-1])[2]["position"].shape[0] == n  # the born ones are in


def test_plain_erosion_from_a_deck_reports_the_lost_mass(tmp_path):
    sim = Simulation.from_deck(loads_deck(cube(erosion='[mesh.erosion]\nto = "nothing"')),
                               tmp_path / "run")
    m0 = sim.stepper.part("cube").nodes.m.sum()
    sim.run()
    h = read_history_csv(tmp_path / "run/history.csv")
    assert h["eroded_cube"][-1] > 0
    lost = h["m_eroded_cube"][-1]
    assert lost > 0
    assert sim.stepper.part("cube").nodes.m.sum() + lost == pytest.approx(m0, rel=1e-12)
    assert h["E_removed"][-1] == h["E_eroded_cube"][-1] > 0


def test_restart_across_conversions_from_a_deck_is_bitwise(tmp_path):
    """With the interactions' own work books on (``interaction_work``): their
    columns restart bitwise too, and add up to -E_contact."""
    books = "interaction_work = true"
    full = Simulation.from_deck(loads_deck(cube(extra=books)), tmp_path / "full")
    full.run()
    part = Simulation.from_deck(loads_deck(cube(extra="checkpoint_every = 40\n" + books)),
                                tmp_path / "part")
    part.run(max_steps=170)
    ck = read_checkpoint(tmp_path / "part/checkpoint.h5")
    assert 0 < ck[1]["t"] < 3e-4
    assert main(["restart", str(tmp_path / "part"), "-q"]) == 0
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert list(h_full) == list(h_part)
    for col in h_full:
        assert np.array_equal(h_full[col], h_part[col]), col
    books = [c for c in h_full if c.startswith("W_contact_")]
    assert sorted(books) == ["W_contact_cube_debris", "W_contact_events",
                             "W_contact_floor", "W_contact_floor_cube"]
    total = sum(h_full[c] for c in books)
    assert np.allclose(total, -h_full["E_contact"], rtol=0, atol=1e-9 * np.abs(total).max())
    f_full = read_frame(sorted((tmp_path / "full/frames").glob("*.h5"))[-1])[2]
    f_part = read_frame(sorted((tmp_path / "part/frames").glob("*.h5"))[-1])[2]
    assert np.array_equal(f_full["position"], f_part["position"])


# ------------------------------------------------------------------ bad input
def test_damage_rule_on_a_model_without_damage_is_refused(tmp_path, capsys):
    _bad(tmp_path, cube(rules="[material.erosion]\nerode = 1.05"),
         "material[0] 'concrete'.erosion.erode", ["no damage variable"], capsys)


def test_eroding_mesh_without_rules_is_refused(tmp_path, capsys):
    _bad(tmp_path, cube(rules=""), "mesh[0] 'cube'.erosion", ["no material", "rules"],
         capsys)


def test_rule_table_without_a_rule_is_refused(tmp_path, capsys):
    _bad(tmp_path, cube(rules="[material.erosion]"), "material[0]", ["no rule"], capsys)


def test_particle_keys_with_plain_erosion_are_refused(tmp_path, capsys):
    _bad(tmp_path, cube(erosion='[mesh.erosion]\nto = "nothing"\nparticles_per_element = 8'),
         "mesh[0]", ["particles_per_element", "nothing"], capsys)


def test_erosion_into_particles_with_a_tied_coupling_is_refused(tmp_path, capsys):
    conv = ('convert = {region = {shape = "box", lo = [0, 0, 0], hi = [0.04, 0.04, 0.02]}, '
            'coupling = "tied"}\n' + TO_PARTICLES)
    _bad(tmp_path, cube(erosion=conv), "mesh[0]", ["tied", "penalty"], capsys)


def test_eroded_elements_leave_the_mesh_frames(tmp_path):
    """The mesh block of the frames holds the remaining elements only, with
    cell fields of the same length."""
    from sphdyn.io import read_frame_meshes

    sim = Simulation.from_deck(loads_deck(cube(t_end="0.15 ms", every="0.15 ms")),
                               tmp_path / "run")
    sim.run()
    el = sim.stepper.part("cube").el
    assert 0 < int(el.active.sum()) < el.n
    mesh = read_frame_meshes(sorted((tmp_path / "run/frames").glob("*.h5"))[-1])["cube"]
    assert mesh.cells.shape[0] == int(el.active.sum())
    assert np.array_equal(mesh.cells, el.conn[el.active == 1])
    assert all(v.shape[0] == mesh.cells.shape[0] for v in mesh.cell_data.values())
