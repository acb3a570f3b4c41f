"""Finite-element parts from decks: [[mesh]], mesh node sets, boundaries, loads, walls.

What is pinned here, with its tolerance:

* a bar of hexes (nu = 0) pulled slowly by a prescribed displacement from a
  deck: both reactions equal E A d / L within 0.5 % (uniform strain is exact
  in one-point hexes; what is left is the ringing after the smooth ramp,
  damped by the deck's mass damping);
* a cantilever of beams from [mesh.line] with a [[load]] at its tip and a
  clamped root (rotations fixed): the tip deflection P L^3 / (3 E I) within
  2 % with I of the section's local z side (width along the orientation
  vector, height across): swapping the two would be 4x off;
* a mesh read from an Abaqus file with two element groups of two materials
  gives the nodal masses of the groups' densities (1e-12) and the same
  motion as the generated block (bitwise, same node order);
* [mesh.convert]: one particle per converted element, the total mass of
  particles and remaining elements equals the whole mesh's (1e-12);
* a wall on mesh nodes: the momentum change of the mesh equals the wall's
  impulse column (1e-9 relative);
* restart of a run with a mesh continues bitwise;
* output: the mesh block in the .pvd, .vtu and .h5 frames with its cell
  fields, the reactions in the history and plots/reactions.png;
* bad input: a missing or unreadable mesh file, an inverted element (named
  by id), an unknown group, an empty node set, a conversion region without
  elements, rotations on solid nodes, a probe of mesh nodes: each a clear
  error naming the field, exit status 2, nothing written.
"""

from __future__ import annotations

import json

import meshio
import numpy as np
import pytest

from decks import ROLLERS
from sphdyn.build import build_stepper
from sphdyn.cli import main
from sphdyn.deck import DeckError, loads_deck
from sphdyn.geometry.mesh_blocks import block_mesh
from sphdyn.watchers.guards import SimulationFailed
from sphdyn.io import read_checkpoint, read_frame_meshes, read_history_csv
from sphdyn.build.model import build_model
from sphdyn.simulation import Simulation

E, RHO = 210e9, 7850.0
C_BAR = np.sqrt(E / RHO)

MATERIALS = f"""
[[material]]
name = "steel"
model = "elastic"
density = {RHO}
E = {E}
nu = 0.0
[[material]]
name = "heavy"
model = "elastic"
density = {2 * RHO}
E = {E}
nu = 0.0
"""

#: a 1 m bar of 10 x 1 x 1 hexes (0.1 m square), left end fixed, right end
#: pulled 0.1 mm along x over a smooth ramp of 2 ms, damped
BAR = """
[run]
dimension = 3
t_end = "{t_end}"
{materials}
[[mesh]]
name = "bar"
material = "steel"
damping = "{damping}"
{source}
[[set]]
name = "left"
mesh = "bar"
region = {{shape = "box", lo = [-0.001, -1, -1], hi = [0.001, 1, 1]}}
[[set]]
name = "right"
mesh = "bar"
region = {{shape = "box", lo = [0.999, -1, -1], hi = [1.001, 1, 1]}}
[[boundary]]
set = "left"
type = "fixed"
[[boundary]]
set = "right"
type = "displacement"
displacement = ["0.1 mm", 0, 0]
ramp_time = "2 ms"
ramp = "smooth"
[output]
every = "{every}"
progress = false
{extra}
"""
BLOCK = 'block = {lo = [0, 0, 0], hi = [1, 0.1, 0.1], divisions = [10, 1, 1]}'


def bar_deck(t_end="3 ms", every="1 ms", source=BLOCK, damping="5000 1/s", extra="",
             base_dir="."):
    return loads_deck(BAR.format(t_end=t_end, every=every, source=source, damping=damping,
                                 materials=MATERIALS, extra=extra), base_dir=base_dir)


def test_bar_reactions_from_a_deck_equal_EA_d_over_L(tmp_path):
    sim = Simulation.from_deck(bar_deck(), tmp_path / "bar")
    summary = sim.run()
    assert summary["status"] == "completed"
    h = read_history_csv(tmp_path / "bar/history.csv")
    expected = E * 0.1 * 0.1 * 1e-4 / 1.0
    assert h["right_reaction_x"][-1] == pytest.approx(expected, rel=5e-3)
    assert h["left_reaction_x"][-1] == pytest.approx(-expected, rel=5e-3)
    # quasi-static at the end: the kinetic energy is a tiny part of the internal
    assert h["KE_IE_ratio"][-1] < 1e-3
    # output: the mesh block beside the (empty) particle block
    pvd = (tmp_path / "bar/particles.pvd").read_text()
    assert 'name="bar"' in pvd
    vtus = sorted((tmp_path / "bar/vtk/bar").glob("frame_*.vtu"))
    m = meshio.read(vtus[-1])
    assert m.cells[0].type == "hexahedron" and len(m.cells[0].data) == 10
    for name in ("stress", "von_mises", "hourglass_energy", "damage"):
        assert name in m.cell_data, name
    assert np.allclose(m.point_data["displacement"][:, 0].max(), 1e-4, rtol=1e-9)
    meshes = read_frame_meshes(sorted((tmp_path / "bar/frames").glob("*.h5"))[-1])
    assert meshes["bar"].cells.shape == (10, 8)
    assert meshes["bar"].cell_data["stress"].shape == (10, 3, 3)
    assert (tmp_path / "bar/plots/reactions.png").is_file()
    info = json.loads((tmp_path / "bar/summary.json").read_text())
    assert info["meshes"] == {"bar": {"nodes": 44, "elements": 10}}
    # a mesh-only run has no particles: its 44 nodes are counted as nodes
    # (the summary said "particles": 44), the rate counts both as items
    assert (info["particles"], info["nodes"], info["items"]) == (0, 44, 44)


def test_frames_carry_the_masses_so_momentum_can_be_summed_from_them(tmp_path):
    """A frame's particles and mesh nodes carry their masses (HDF5 and VTK),
    whatever output.fields names (here only velocity), so the momentum summed
    from a frame is the model's: the bar moving at 5 m/s with a region turned
    into particles, stopped after 20 steps (the stop frame holds the last
    state). Both sums add the same numbers in the same order: equal bits."""
    import meshio

    from sphdyn.io import read_frame

    source = BLOCK + ('\nvelocity = [0, "5 m/s", 0]\nconvert = {region = {shape = "box", '
                      'lo = [0.3, -1, -1], hi = [0.7, 1, 1]}}')
    sim = Simulation.from_deck(bar_deck(source=source, extra='fields = ["velocity"]'),
                               tmp_path / "run")
    sim.run(max_steps=20)
    frame = sorted((tmp_path / "run/frames").glob("*.h5"))[-1]
    _, _, particles, _ = read_frame(frame)
    nodes = read_frame_meshes(frame)["bar"].point_data

    def momentum(pairs):
        return sum((m[:, None] * v).sum(axis=0) for m, v in pairs)

    from_frame = momentum([(particles["mass"], particles["velocity"]),
                           (nodes["mass"], nodes["velocity"])])
    model = momentum([(part.kin.m, part.kin.v) for part in sim.stepper.parts])
    assert np.array_equal(from_frame, model)
    assert model[1] > 0.25 * RHO * 0.01 * 5.0  # the bar moves (its ends are held)
    vtk = tmp_path / "run/vtk"
    last = sorted(vtk.glob("frame_*.vtu"))[-1].name
    assert np.array_equal(meshio.read(vtk / last).point_data["mass"], particles["mass"])
    assert np.array_equal(meshio.read(vtk / "bar" / last).point_data["mass"], nodes["mass"])


def _abaqus(path, groups: bool):
    """The BAR block written as an Abaqus file (same node and element order);
    with ``groups`` the first 5 elements in ELSET LEFT, the rest in RIGHT."""
    ref = block_mesh((0, 0, 0), (1, 0.1, 0.1), (10, 1, 1), 3)
    lines = ["*NODE"] + [f"{i + 1}, " + ", ".join(repr(float(v)) for v in p)
                         for i, p in enumerate(ref.points)]
    lines += ["*ELEMENT, TYPE=C3D8R, ELSET=ALL"]
    lines += [f"{k + 1}, " + ", ".join(str(n + 1) for n in c) for k, c in enumerate(ref.cells)]
    if groups:
        lines += ["*ELSET, ELSET=LEFT", "1, 2, 3, 4, 5", "*ELSET, ELSET=RIGHT",
                  "6, 7, 8, 9, 10"]
    path.write_text("\n".join(lines) + "\n")
    return ref


def test_abaqus_file_with_groups_gives_the_block_and_the_groups_materials(tmp_path):
    ref = _abaqus(tmp_path / "bar.inp", groups=True)
    source = ('file = "bar.inp"\n[[mesh.group]]\nname = "LEFT"\nmaterial = "steel"\n'
              '[[mesh.group]]\nname = "RIGHT"\nmaterial = "heavy"')
    deck = bar_deck(source=source, base_dir=tmp_path)
    part = build_stepper(deck).part("bar")
    vol = 0.01 * 0.1
    share = np.zeros(ref.n_nodes)
    for k, c in enumerate(ref.cells):
        share[c] += (RHO if k < 5 else 2 * RHO) * vol / 8
    assert np.allclose(part.nodes.m, share, rtol=1e-12, atol=0)
    # a file without groups moves exactly as the generated block
    _abaqus(tmp_path / "plain.inp", groups=False)
    a = build_stepper(bar_deck(source='file = "plain.inp"', base_dir=tmp_path))
    b = build_stepper(bar_deck())
    for _ in range(30):
        a.step()
        b.step()
    assert np.array_equal(a.part("bar").nodes.x, b.part("bar").nodes.x)


def test_a_mesh_file_in_millimetres_moved_by_translate_lands_where_it_should(tmp_path):
    """length_unit scales the file's coordinates, then translate shifts them:
    the bar written in millimetres 5 mm below its place ends exactly where
    the file in metres puts it (x = 1 mm and 0.5 mm are exact in binary
    after the scaling only to round-off: compared to 1e-15 m)."""
    ref = block_mesh((0, 0, 0), (1, 0.1, 0.1), (10, 1, 1), 3)
    lines = ["*NODE"] + [f"{i + 1}, " + ", ".join(repr(float(v)) for v in 1e3 * p
                                                   - np.array([0.0, 0.0, 5.0]))
                         for i, p in enumerate(ref.points)]
    lines += ["*ELEMENT, TYPE=C3D8R, ELSET=ALL"]
    lines += [f"{k + 1}, " + ", ".join(str(n + 1) for n in c) for k, c in enumerate(ref.cells)]
    (tmp_path / "mm.inp").write_text("\n".join(lines) + "\n")
    deck = bar_deck(source='file = "mm.inp"\nlength_unit = "1 mm"\n'
                           'translate = [0, 0, "5 mm"]', base_dir=tmp_path)
    part = build_stepper(deck).part("bar")
    assert np.allclose(part.nodes.x, ref.points, rtol=0, atol=1e-15)
    # without the shift the nodes are 5 mm low
    deck = bar_deck(source='file = "mm.inp"\nlength_unit = "1 mm"', base_dir=tmp_path)
    assert np.allclose(build_stepper(deck).part("bar").nodes.x[:, 2], ref.points[:, 2] - 5e-3,
                       rtol=0, atol=1e-15)


def test_translate_belongs_to_mesh_files():
    with pytest.raises(DeckError, match="translate moves a mesh file"):
        bar_deck(source=BLOCK + '\ntranslate = [0, 0, "1 mm"]')


CANTILEVER = """
[run]
dimension = 3
t_end = "{t_end}"
{materials}
[[mesh]]
name = "rod"
material = "steel"
element = "beam"
line = {{start = [0, 0, 0], end = [1, 0, 0], divisions = 20}}
section = {{shape = "rectangle", width = "40 mm", height = "80 mm", orientation = [0, 1, 0]}}
damping = "{damping}"
[[set]]
name = "root"
mesh = "rod"
region = {{shape = "box", lo = [-0.001, -1, -1], hi = [0.001, 1, 1]}}
[[set]]
name = "tip"
mesh = "rod"
region = {{shape = "box", lo = [0.999, -1, -1], hi = [1.001, 1, 1]}}
[[boundary]]
set = "root"
type = "fixed"
rotations = "fixed"
[[load]]
set = "tip"
force = [0, 0, "-1 kN"]
ramp_time = "{ramp}"
ramp = "smooth"
[output]
progress = false
vtk = false
"""


def test_output_fields_name_the_cells_of_meshes_too():
    """The output-field registry covers mesh cells: every cell field a solid,
    a beam and a truss part offers is registered as a cell field (or is a
    history column of its material), and the deck's output.fields picks the
    ones a mesh frame writes; the particles' frame skips the cells' fields."""
    from sphdyn.fields import FIELDS, default_fields
    from sphdyn.io import particle_fields

    solid = bar_deck()
    beam = CANTILEVER.format(materials=MATERIALS, damping="0 1/s", ramp="1 ms",
                             t_end="1 ms")
    truss = beam.replace('element = "beam"', 'element = "truss"').replace(
        'rotations = "fixed"\n', '')
    offered = set()
    for deck in (solid, loads_deck(beam), loads_deck(truss)):
        for part in build_stepper(deck).parts:
            fields = part.fields()
            history = set(getattr(getattr(part, "pts", None), "hist_names", ()))
            history |= set(getattr(getattr(part, "model", None), "history_names", ()))
            for name in fields:
                assert name in history or (name in FIELDS and FIELDS[name].cells), name
            offered |= set(fields)
            # the defaults write every cell field a part has (as before the
            # registry knew them); a named list only those named
            assert set(part.frame().cell_data) == set(fields)
            picked = [n for n in fields if n in ("von_mises", "axial_force")]
            assert set(part.frame(["velocity", *picked]).cell_data) == set(picked)
    assert {"hourglass_energy", "axial_force", "moment_y", "lateral_stress"} <= offered
    assert {"hourglass_energy", "axial_force"} <= set(default_fields())
    deck = bar_deck(extra='fields = ["velocity", "axial_force", "hourglass_energy"]')
    assert set(particle_fields(build_model(deck).particles, list(deck.output.fields))) \
        == {"position", "mass", "velocity"}


def test_cantilever_of_beams_from_a_deck_deflects_as_PL3_over_3EI():
    # I about the local y axis: the height (80 mm) runs along local z = x X y
    # = global z, the load's direction: I = b h^3 / 12
    i_y = 0.04 * 0.08 ** 3 / 12.0
    m_line = RHO * 0.04 * 0.08
    omega1 = 1.875 ** 2 * np.sqrt(E * i_y / (m_line * 1.0 ** 4))  # first bending mode
    period = 2 * np.pi / omega1
    deck = loads_deck(CANTILEVER.format(materials=MATERIALS, damping=f"{2 * omega1} 1/s",
                                        ramp=f"{3 * period} s", t_end=f"{6 * period} s"))
    s = build_stepper(deck)
    while s.t < deck.run.t_end:
        s.step(t_stop=deck.run.t_end)
    rod = s.part("rod")
    tip = np.argmax(rod.kin.x0[:, 0])
    expected = 1000.0 * 1.0 ** 3 / (3 * E * i_y)
    assert -rod.kin.x[tip, 2] == pytest.approx(expected, rel=0.02)
    assert abs(rod.kin.x[tip, 1]) < 1e-6 * expected  # no sideways bending
    assert s.record()["tip_force"] == pytest.approx(1000.0)


def test_a_load_books_its_work_as_external_and_restarts_bitwise():
    """The [[load]]'s work is external (W_external = W_tip + the clamp's,
    which does none: 1e-12) and positive under the load's own deflection; a
    run restored in the middle of the ramp continues with the same bits
    (the load's state: its ramp value, work and accelerations)."""
    from stepping import restarted_pair

    deck = loads_deck(CANTILEVER.format(materials=MATERIALS, damping="0 1/s",
                                        ramp="2 ms", t_end="1 s"))

    def advance(st):
        for _ in range(30):
            st.step()

    st, st2 = restarted_pair(deck, advance, 30)
    r, r2 = st.record(), st2.record()
    assert r["W_tip"] > 0.0
    assert r["W_external"] == pytest.approx(r["W_tip"], rel=1e-12)
    assert r["W_tip"] == r2["W_tip"] and r["E_total"] == r2["E_total"]
    assert np.array_equal(st.part("rod").kin.x, st2.part("rod").kin.x)


def test_converted_region_keeps_the_mass_and_gives_one_particle_per_element():
    source = BLOCK + ('\nconvert = {region = {shape = "box", lo = [0.3, -1, -1], '
                      'hi = [0.7, 1, 1]}}')
    deck = bar_deck(source=source)
    model = build_model(deck)
    s = build_stepper(deck, model)
    assert model.particles.n == 4  # element centroids at x = 0.35 .. 0.65
    assert model.body_names == ["bar"]
    total = s.part("bar").nodes.m.sum() + model.particles.m.sum()
    assert total == pytest.approx(RHO * 0.01, rel=1e-12)
    assert np.allclose(model.particles.vol0, 1e-3, rtol=1e-12)
    assert [i.name for i in s.interactions][-1] == "bar_coupling"


FALLING = """
[run]
dimension = 3
t_end = "{t_end}"
{materials}
[[mesh]]
name = "cube"
material = "steel"
block = {{lo = [0, 0.001, 0], hi = [0.1, 0.101, 0.1], divisions = [2, 2, 2]}}
velocity = [0, "-5 m/s", 0]
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
thickness_factor = 0  # contact at the plane: the cube starts 1 mm above it
[output]
progress = false
vtk = false
history_every = 1
"""


def test_wall_on_mesh_nodes_gives_the_impulse_of_the_momentum_change():
    deck = loads_deck(FALLING.format(materials=MATERIALS, t_end="0.5 ms"))
    s = build_stepper(deck)
    q = s.part("cube").kin
    p0 = (q.m[:, None] * q.v).sum(axis=0)
    hit = 0
    while s.t < deck.run.t_end:
        s.step(t_stop=deck.run.t_end)
        hit = max(hit, s.record()["contacts_floor_cube"])
    assert hit > 0
    # the kick's velocities are v^{n+1/2}: their momentum minus the initial
    # one is the sum of the wall's F dt_kick, the impulse column
    p1 = (q.m[:, None] * q.v).sum(axis=0)
    impulse = s.record()["I_wall_floor_cube"]
    assert impulse > 0.5 * q.m.sum() * 5.0  # the cube did bounce
    assert p1[1] - p0[1] == pytest.approx(impulse, rel=1e-9)


def test_restart_with_a_mesh_is_bitwise(tmp_path):
    full = Simulation.from_deck(bar_deck(t_end="0.6 ms", every="0.2 ms"), tmp_path / "full")
    full.run()
    part = Simulation.from_deck(bar_deck(t_end="0.6 ms", every="0.2 ms",
                                         extra="checkpoint_every = 10"), tmp_path / "part")
    part.run(max_steps=25)
    assert 0 < read_checkpoint(tmp_path / "part/checkpoint.h5")[1]["t"] < 6e-4
    assert main(["restart", str(tmp_path / "part"), "-q"]) == 0
    m_full = read_frame_meshes(sorted((tmp_path / "full/frames").glob("*.h5"))[-1])["bar"]
    m_part = read_frame_meshes(sorted((tmp_path / "part/frames").glob("*.h5"))[-1])["bar"]
    assert np.array_equal(m_full.points, m_part.points)
    for data in ("point_data", "cell_data"):
        for key, arr in getattr(m_full, data).items():
            assert np.array_equal(arr, getattr(m_part, data)[key]), key
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert np.array_equal(h_full["right_reaction_x"], h_part["right_reaction_x"])
    assert np.array_equal(h_full["E_total"], h_part["E_total"])


def test_nan_on_a_node_stops_the_run_naming_the_mesh(tmp_path):
    sim = Simulation.from_deck(bar_deck(), tmp_path / "nan")
    nodes = sim.stepper.part("bar").nodes
    nodes.v[np.argmin(np.abs(nodes.x0[:, 0] - 0.5)), 1] = np.nan  # a free node
    with pytest.raises(SimulationFailed, match="node\\(s\\) of mesh 'bar'"):
        sim.run(max_steps=5)
    assert (tmp_path / "nan/history.csv").is_file()


# ------------------------------------------------------------------ bad input
def _bad(tmp_path, text: str, path: str, words: list[str], capsys):
    deck = tmp_path / "bad.toml"
    deck.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(deck), "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    line = next((ln for ln in err.splitlines() if path in ln), None)
    assert line is not None, err
    for w in words:
        assert w in line, (w, line)
    assert "Fix:" in line
    assert not out.exists()


def _bar_text(source=BLOCK, extra=""):
    return BAR.format(t_end="1 ms", every="1 ms", source=source, damping="0 1/s",
                      materials=MATERIALS, extra=extra)


def test_a_graded_block_from_a_deck_puts_its_small_elements_where_asked():
    """[mesh.block] grading: the bar's nodes along x are graded_nodes' (bits),
    and its step is set by its smallest element, the last along x (the
    element the step names), shorter than the equal bar's."""
    from sphdyn.geometry.mesh_blocks import graded_nodes

    graded = BLOCK.replace("divisions = [10, 1, 1]}",
                           'divisions = [10, 1, 1], grading = [{ ratio = 4, smallest = '
                           '"hi" }, { ratio = 1 }, { ratio = 1 }]}')
    st = build_stepper(loads_deck(_bar_text(source=graded)))
    eq = build_stepper(loads_deck(_bar_text()))
    xs = np.unique(st.part("bar").kin.x[:, 0])
    assert np.array_equal(xs, graded_nodes(0.0, 1.0, 10, 4.0, "hi"))
    dt, k, part = st.stable_dt()
    assert part.name == "bar" and k == 9
    assert dt < eq.stable_dt()[0]


@pytest.mark.parametrize("grading, words", [
    ('[{ ratio = 2 }]', ["grading has 1 entries in a 3D deck"]),
    ('[{ ratio = 0.5 }, { ratio = 1 }, { ratio = 1 }]', ["size ratio"]),
    ('[{ ratio = 2, smallest = "middle" }, { ratio = 1 }, { ratio = 1 }]', ["smallest"]),
])
def test_bad_grading_is_refused(tmp_path, capsys, grading, words):
    graded = BLOCK.replace("divisions = [10, 1, 1]}",
                           f"divisions = [10, 1, 1], grading = {grading}}}")
    _bad(tmp_path, _bar_text(source=graded), "mesh[0]", words, capsys)


def test_missing_mesh_file_is_refused(tmp_path, capsys):
    _bad(tmp_path, _bar_text(source='file = "nowhere.msh"'), "mesh[0].file",
         ["does not exist"], capsys)


def test_unreadable_mesh_file_is_refused(tmp_path, capsys):
    (tmp_path / "junk.msh").write_text("this is not a mesh\n")
    _bad(tmp_path, _bar_text(source='file = "junk.msh"'), "mesh[0] 'bar'.file",
         ["cannot be used"], capsys)


def test_inverted_element_is_named_by_id(tmp_path, capsys):
    ref = _abaqus(tmp_path / "bar.inp", groups=False)
    text = (tmp_path / "bar.inp").read_text().splitlines()
    k = text.index("*ELEMENT, TYPE=C3D8R, ELSET=ALL") + 7  # element 7
    c = ref.cells[6] + 1
    mirrored = np.concatenate([c[4:], c[:4]])  # top and bottom faces swapped
    text[k] = "7, " + ", ".join(map(str, mirrored))
    (tmp_path / "bar.inp").write_text("\n".join(text) + "\n")
    _bad(tmp_path, _bar_text(source='file = "bar.inp"'), "mesh[0] 'bar'",
         ["inverted", "ids 7"], capsys)


def test_unknown_group_is_refused(tmp_path, capsys):
    _abaqus(tmp_path / "bar.inp", groups=True)
    source = 'file = "bar.inp"\n[[mesh.group]]\nname = "MIDDLE"\nmaterial = "steel"'
    _bad(tmp_path, _bar_text(source=source), "mesh[0] 'bar'.group[0].name",
         ["no element group 'MIDDLE'", "LEFT"], capsys)


def test_empty_node_set_is_refused(tmp_path, capsys):
    text = _bar_text().replace("lo = [0.999, -1, -1], hi = [1.001, 1, 1]",
                               "lo = [2, -1, -1], hi = [3, 1, 1]")
    _bad(tmp_path, text, "set[1] 'right'", ["holds no node"], capsys)


def test_conversion_region_without_elements_is_refused(tmp_path, capsys):
    source = BLOCK + '\nconvert = {region = {shape = "box", lo = [5, 5, 5], hi = [6, 6, 6]}}'
    _bad(tmp_path, _bar_text(source=source), "mesh[0] 'bar'.convert.region",
         ["no element centroid"], capsys)


def test_an_unstable_hourglass_coefficient_is_refused(tmp_path, capsys):
    """Past 0.15 (the viscous form amplifies a cube's hourglass mode from 0.24:
    test_fem_solid.py) the deck names the field and its range."""
    _bad(tmp_path, _bar_text(source=BLOCK + "\nhourglass_coefficient = 0.3"),
         "mesh[0].hourglass_coefficient", ["0.15", "mesh 'bar'"], capsys)


def test_rotations_on_solid_nodes_are_refused(tmp_path, capsys):
    text = _bar_text().replace('type = "fixed"\n', 'type = "fixed"\nrotations = "fixed"\n', 1)
    _bad(tmp_path, text, "boundary[0].rotations", ["no rotational"], capsys)


def test_probe_of_mesh_nodes_records_their_kinematics(tmp_path):
    """A [[probe]] of a mesh's node set (LS-DYNA's nodout): the bar's right
    end is pulled 0.1 mm over the 2 ms smooth ramp, so at every record the
    probe's mean displacement_x is the prescribed displacement of the ramp at
    that time (the nodes follow it exactly: to round-off, 1e-12 m), its
    velocity_x the ramp's velocity within one step of its change (the kick's
    velocity is the ramp's over the step: |dv/dt| dt, 3e-3 m/s at the ramp's
    largest acceleration, of a peak of 0.1 m/s); "max" of position_x is 1 m
    plus the displacement. A probe without quantities records the default
    ones that nodes have (not von_mises); the fixed end stays at zero."""
    text = _bar_text(extra="") + (
        '\n[[probe]]\nset = "right"\nquantities = ["displacement_x", "velocity_x"]'
        '\n[[probe]]\nset = "right"\nquantities = ["position_x"]\nreduce = "max"\n'
        '\n[[probe]]\nset = "left"\n')
    sim = Simulation.from_deck(loads_deck(text), tmp_path / "bar")
    assert sim.run()["status"] == "completed"
    h = read_history_csv(tmp_path / "bar/history.csv")
    t = h["time"] / 2e-3
    ramp = np.where(t < 1.0, t - np.sin(2 * np.pi * t) / (2 * np.pi), 1.0)  # smooth
    rate = np.where(t < 1.0, (1.0 - np.cos(2 * np.pi * t)) / 2e-3, 0.0)
    assert np.abs(h["probe_right_displacement_x"] - 1e-4 * ramp).max() < 1e-12
    slope = 1e-4 * 2 * np.pi / 2e-3 ** 2  # the ramp's largest acceleration [m/s^2]
    assert np.abs(h["probe_right_velocity_x"] - 1e-4 * rate).max() < slope * h["dt"].max()
    assert np.abs(h["probe_right_position_x"] - 1.0 - 1e-4 * ramp).max() < 1e-12
    # the default quantities that nodes have: the displacements and velocities
    assert sorted(k for k in h if k.startswith("probe_left")) == sorted(
        f"probe_left_{f}_{c}" for f in ("displacement", "velocity") for c in "xyz")
    assert np.all(h["probe_left_displacement_x"] == 0.0)


def test_probe_of_mesh_nodes_names_what_nodes_have(tmp_path, capsys):
    text = _bar_text(extra="") + '\n[[probe]]\nset = "left"\nquantities = ["stress_xx"]\n'
    _bad(tmp_path, text, "probe[0].quantities", ["'stress_xx' is not a quantity of mesh "
                                                 "nodes", "displacement"], capsys)


def test_huge_generated_mesh_is_refused_before_it_is_made(tmp_path, capsys):
    source = 'block = {lo = [0, 0, 0], hi = [1, 0.1, 0.1], divisions = [100000, 1000, 1000]}'
    _bad(tmp_path, _bar_text(source=source), "mesh[0].block.divisions",
         ["memory limit", "1e+11 elements"], capsys)


def test_deck_schema_refuses_inconsistent_meshes(tmp_path):
    (tmp_path / "x.msh").write_text("")
    with pytest.raises(DeckError, match="exactly one source"):
        bar_deck(source=BLOCK + '\nfile = "x.msh"', base_dir=tmp_path)
    with pytest.raises(DeckError, match="needs element and"):
        bar_deck(source='line = {start = [0, 0, 0], end = [1, 0, 0], divisions = 4}')
    with pytest.raises(DeckError, match="divisions has 2 entries"):
        bar_deck(source='block = {lo = [0, 0, 0], hi = [1, 1, 1], divisions = [2, 2]}')
    with pytest.raises(DeckError, match="displacement boundary needs a ramp_time"):
        loads_deck(_bar_text().replace('ramp_time = "2 ms"', ""))
    # a displacement along a direction the condition leaves free, a repeated one
    with pytest.raises(DeckError, match="has a x component, but components = \\['y'\\]"):
        loads_deck(_bar_text().replace('ramp = "smooth"', 'ramp = "smooth"\ncomponents = ["y"]'))
    with pytest.raises(DeckError, match="at most once"):
        loads_deck(_bar_text().replace('type = "fixed"', 'type = "fixed"\ncomponents = ["x", "x"]'))
    with pytest.raises(DeckError, match="components"):
        loads_deck(_bar_text().replace('type = "fixed"', 'type = "fixed"\ncomponents = ["w"]'))
    with pytest.raises(DeckError, match="no \\[\\[body\\]\\] table"):
        loads_deck('[run]\ndimension = 3\nt_end = 1.0\n' + MATERIALS)


#: a steel block of selective-reduced hexes at 200 m/s onto a rigid wall with
#: the default contact thickness: the whole block, or its quarter x, y >= 0
#: with rollers on the planes x = 0 and y = 0 (issue 57's set-up, elastic)
QUARTER = """
[run]
dimension = 3
t_end = "{t_end}"
{materials}
[[mesh]]
name = "block"
material = "steel"
integration = "selective_reduced"
block = {{lo = [{lo}, {lo}, "5.5 mm"], hi = ["20 mm", "20 mm", "25.5 mm"], divisions = [{n}, {n}, 2]}}
velocity = [0, 0, "-200 m/s"]
{rollers}
[[wall]]
name = "rigid"
point = [0, 0, 0]
normal = [0, 0, 1]
[output]
progress = false
vtk = false
"""



def test_a_quarter_model_with_rollers_meets_a_wall_as_the_whole_model_does():
    """Issue 57: the quarter of a block (rollers on its symmetry planes) and the
    whole block strike a wall with the default contact thickness (half an
    element, 5 mm); at 12 us, the contact under way since 2.5 us, every node
    of the quarter is where its node of the whole block is, within 1e-9 of
    the block's size (the two differ in summation order only). A node's
    contact thickness was f_t times the cube root of its share of its
    elements' volume, on the symmetry planes a half (their edge of the struck
    face) or a quarter (the corner, the centre of the struck face) of the
    whole model's share: the quarter's nodes there met the wall later, and
    at 12 us were 0.18 mm off (the dent that crushed the centre element)."""
    runs = []
    for lo, n, rollers in (("\"-20 mm\"", 4, ""), (0, 2, ROLLERS)):
        deck = loads_deck(QUARTER.format(materials=MATERIALS, t_end="12 us", lo=lo, n=n,
                                         rollers=rollers))
        s = build_stepper(deck)
        while s.t < deck.run.t_end * (1 - 1e-12):
            s.step(t_stop=deck.run.t_end)
        q = s.part("block").kin
        assert s.record()["contacts_rigid_block"] > 0
        runs.append((q.x0, q.x))
    (x0_all, x_all), (x0_q, x_q) = runs
    key = lambda x0: np.round(x0 * 1e6).astype(np.int64)  # noqa: E731 (um grid)
    where = {tuple(k): i for i, k in enumerate(key(x0_all))}
    match = np.array([where[tuple(k)] for k in key(x0_q)])
    assert np.abs(x_q - x_all[match]).max() < 1e-9 * 0.04


def test_sets_and_gauges_name_the_particles_of_a_converted_mesh_by_the_mesh_name(capsys):
    """The particles of a [mesh.convert] form a body named as the mesh (the
    docs say so), and a [[set]] or [[gauge]] may name it: `body = "bar"` was
    refused with "there is no body named 'bar'". The set holds exactly the
    converted particles (all of them, or those in its region); the gauge
    sits on the converted particle nearest its point."""
    source = BLOCK + ('\nconvert = {region = {shape = "box", lo = [0.3, -1, -1], '
                      'hi = [0.7, 1, 1]}}')
    extra = """
[[set]]
name = "converted"
body = "bar"
[[set]]
name = "right_half"
body = "bar"
region = {shape = "box", lo = [0.5, -1, -1], hi = [1, 1, 1]}
[[gauge]]
name = "mid"
type = "point"
body = "bar"
point = [0.45, 0.05, 0.05]
"""
    deck = bar_deck(source=source, extra=extra)
    model = build_model(deck)
    assert model.body_names == ["bar"]
    assert np.array_equal(model.sets["converted"], np.arange(4))
    assert np.allclose(model.particles.x[model.sets["right_half"], 0], [0.55, 0.65])
    from sphdyn.watchers.gauges import build_gauges

    parts = build_stepper(deck, model).parts
    (gauge,) = build_gauges(deck, parts)
    ((pk, i),) = gauge.items  # the converted particle at x = 0.45 (0.5 m from a node)
    assert parts[pk].kind == "sph" and np.allclose(parts[pk].kin.x0[i], [0.45, 0.05, 0.05])
    with pytest.raises(DeckError, match="there is no body named 'rod'.*bar"):
        bar_deck(source=source, extra=extra.replace('body = "bar"', 'body = "rod"', 1))
    with pytest.raises(DeckError, match="there is no body named 'bar'"):
        bar_deck(extra=extra)  # without [mesh.convert] the mesh makes no particles


def test_empty_particle_set_is_refused(tmp_path, capsys):
    """A [[set]] whose region holds no particle centre (here a 5 mm slice
    between two rows of particles 10 mm apart) is refused before the run: a
    probe on it recorded NaN for the whole run, a boundary on it did nothing."""
    from decks import elastic_steel

    text = elastic_steel(2) + """
[[body]]
name = "plate"
material = "steel"
dx = "10 mm"
geometry = { shape = "box", lo = [0, 0, 0], hi = ["100 mm", "20 mm", 0] }
[[set]]
name = "mid"
body = "plate"
region = { shape = "box", lo = ["46 mm", -1, -1], hi = ["54 mm", 1, 1] }
[[probe]]
set = "mid"
quantities = ["displacement_y"]
"""
    _bad(tmp_path, text, "set[0] 'mid'", ["holds no particle of body 'plate'"], capsys)
