"""``sphdyn import``: LS-DYNA keyword decks become sphdyn decks (issue 55).

The keyword decks are written here from the same lattice and block as an
equivalent TOML deck: the imported model must equal the TOML deck's bit for
bit (every particle and node position, mass, volume, density, smoothing
length, material, velocity; the elements, their materials, the constrained
node sets) and run the same steps to the same state. The fixed, free, long
and included-and-parametrised forms of one deck must import alike; bad decks
fail with one line naming the file, the line and the keyword.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

pytest.importorskip("ansys.dyna.core")

from sphdyn.build.model import build_model  # noqa: E402
from sphdyn.cli import main  # noqa: E402
from sphdyn.deck import load_deck  # noqa: E402
from sphdyn.geometry.lattice import box_lattice  # noqa: E402
from sphdyn.geometry.mesh_blocks import block_mesh  # noqa: E402
from sphdyn.lsdyna import KeywordError, import_deck, write_import  # noqa: E402

DX = 0.002
BALL = ([0.0, 0.0, 0.004], [0.012, 0.006, 0.010])     # SPH box, 6 x 3 x 3
PLATE = ([0.020, 0.0, 0.030], [0.032, 0.008, 0.034], [3, 2, 1])  # hexahedra
T_END = 4e-6

TOML = f"""
[run]
title = "ball and plate"
dimension = 3
t_end = "{T_END!r} s"

[[material]]
name = "concrete"
model = "elastic"
density = "2400.0 kg/m^3"
E = "30000000000.0 Pa"
nu = 0.2

[[material]]
name = "steel"
model = "j2"
density = "7850.0 kg/m^3"
E = "200000000000.0 Pa"
nu = 0.3
yield_stress = "500000000.0 Pa"
hardening_modulus = "{200e9 * 2e9 / (200e9 - 2e9)!r} Pa"

[[body]]
name = "ball"
material = "concrete"
dx = "{DX!r} m"
velocity = [0.0, 0.0, -10.0]
geometry = {{shape = "box", lo = {BALL[0]}, hi = {BALL[1]}}}

[sph]
h_factor = 1.2
smoothing_length = {{mode = "benz", min_factor = 0.2, max_factor = 2.0}}

[[mesh]]
name = "solids"
material = "steel"
block = {{lo = {PLATE[0]}, hi = {PLATE[1]}, divisions = {PLATE[2]}}}
cfl = 0.6
velocity = [0.0, 0.0, 0.0]

[[set]]
name = "base"
mesh = "solids"
region = {{shape = "box", lo = [-1, -1, -1], hi = [1, 1, 0.030000001]}}

[[boundary]]
set = "base"
type = "fixed"
components = ["x", "y", "z"]

[[wall]]
name = "floor"
point = [0.0, 0.0, 0.003]
normal = [0.0, 0.0, 1.0]
"""


def _fmt(value, width: int, form: str) -> str:
    """A field: "free" keeps every digit of a float; the other forms print
    ``%.9g`` ("free9" comma-separated, "fixed" and "long" right-aligned in
    their columns), so that they carry the same numbers."""
    if isinstance(value, float):
        text = repr(value) if form == "free" else f"{value:.9g}"
    else:
        text = str(value)
    if form in ("free", "free9"):
        return text
    assert len(text) <= width, text
    return text.rjust(width)


def _row(values, form: str, widths) -> str:
    sep = "," if form in ("free", "free9") else ""
    return sep.join(_fmt(v, w, form) for v, w in zip(values, widths))


def keyword_deck(form: str = "free") -> dict[str, str]:
    """The TOML deck above as keyword files (name -> text) in ``form``:
    "free" (commas, every digit), "free9" (commas, nine digits), "fixed"
    (8/10/16-character fields), "long" (LONG=Y, 20-character fields) or
    "include" (fixed, the nodes in an *INCLUDE and the steel's yield stress
    a *PARAMETER)."""
    long = form == "long"
    f = "fixed" if form == "include" else form
    i8 = 20 if long else 8
    e16 = 20 if long else 16
    i10 = 20 if long else 10
    x = box_lattice(BALL[0], BALL[1], DX, 3)
    mesh = block_mesh(PLATE[0], PLATE[1], PLATE[2], 3)
    mass = 2400.0 * DX ** 3
    nodes = ["*NODE"]
    nodes += [_row([k + 1, *map(float, p)], f, (i8, e16, e16, e16))
              for k, p in enumerate(x)]
    first = x.shape[0] + 1
    nodes += [_row([first + k, *map(float, p)], f, (i8, e16, e16, e16))
              for k, p in enumerate(mesh.points)]
    base = [first + k for k, p in enumerate(mesh.points) if p[2] <= 0.030000001]
    lines = ["*KEYWORD LONG=Y" if long else "*KEYWORD", "*TITLE", "ball and plate"]
    if form == "include":
        lines += ["*PARAMETER", "R   sigy    500.0e6", "*INCLUDE", "nodes.k"]
    else:
        lines += nodes
    lines += ["*ELEMENT_SPH"]
    lines += [_row([k + 1, 1, mass], f, (i8, i8, e16)) for k in range(x.shape[0])]
    lines += ["*ELEMENT_SOLID"]
    lines += [_row([e + 1, 2, *(first + n for n in c)], f, (i8,) * 10)
              for e, c in enumerate(mesh.cells)]
    sigy = "&sigy" if form == "include" else 500e6
    lines += ["*PART", "ball", _row([1, 1, 1], f, (i10,) * 3),
              "*PART", "plate", _row([2, 2, 2], f, (i10,) * 3),
              "*SECTION_SPH", _row([1, 1.2, 0.2, 2.0], f, (i10,) * 4),
              "*SECTION_SOLID", _row([2, 1], f, (i10,) * 2),
              "*MAT_ELASTIC_TITLE", "concrete",
              _row([1, 2400.0, 30e9, 0.2], f, (i10,) * 4),
              "*MAT_PLASTIC_KINEMATIC_TITLE", "steel",
              _row([2, 7850.0, 200e9, 0.3, sigy, 2e9, 1.0], f, (i10,) * 7),
              "*SET_NODE_LIST", _row([7], f, (i10,))]
    lines += [_row(base[k:k + 8], f, (i10,) * 8) for k in range(0, len(base), 8)]
    lines += ["*BOUNDARY_SPC_SET", _row([7, 0, 1, 1, 1, 0, 0, 0], f, (i10,) * 8),
              "*INITIAL_VELOCITY_GENERATION",
              _row([1, 2, 0.0, 0.0, 0.0, -10.0], f, (i10,) * 6),
              "*RIGIDWALL_PLANAR", _row([0], f, (i10,)),
              _row([0.0, 0.0, 0.003, 0.0, 0.0, 1.003, 0.0], f, (i10,) * 7),
              "*CONTROL_TERMINATION", _fmt(T_END, i10, f),
              "*CONTROL_TIMESTEP", _row([0.0, 0.6], f, (i10,) * 2),
              "*END"]
    files = {"model.k": "\n".join(lines) + "\n"}
    if form == "include":
        files["nodes.k"] = "*KEYWORD\n" + "\n".join(nodes) + "\n*END\n"
    return files


def _write(tmp_path, files: dict[str, str]):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return tmp_path / "model.k"


def _imported_model(tmp_path, form="free"):
    path = _write(tmp_path, keyword_deck(form))
    imp = import_deck(path, "m-s-kg")
    assert not imp.dropped, [d.line() for d in imp.dropped]
    write_import(imp, tmp_path / "model.toml")
    return imp, load_deck(tmp_path / "model.toml")


def test_imported_model_equals_the_toml_decks_bit_for_bit(tmp_path):
    """Free format carries every digit: the same particles, nodes, elements,
    materials, sets and boundary as the TOML deck, to the bit."""
    _, deck = _imported_model(tmp_path)
    (tmp_path / "ref.toml").write_text(TOML)
    ref = load_deck(tmp_path / "ref.toml")
    a, b = build_model(deck), build_model(ref)
    pa, pb = a.particles, b.particles
    for name in ("x", "v", "m", "vol0", "rho0", "h", "mat", "c"):
        np.testing.assert_array_equal(getattr(pa, name), getattr(pb, name), err_msg=name)
    (ma,), (mb,) = a.meshes, b.meshes
    np.testing.assert_array_equal(ma.points, mb.points)
    np.testing.assert_array_equal(ma.cells, mb.cells)
    np.testing.assert_array_equal(ma.mat, mb.mat)
    assert ma.spec.integration == mb.spec.integration == "one_point"
    assert ma.spec.cfl == mb.spec.cfl == 0.6
    (sa,), (sb,) = a.mesh_sets.values(), b.mesh_sets.values()
    np.testing.assert_array_equal(np.sort(sa[1]), np.sort(sb[1]))
    for ga, gb in zip(a.groups, b.groups):
        np.testing.assert_array_equal(ga.params, gb.params)
    assert [w.point.tolist() for w in a.walls] == [w.point.tolist() for w in b.walls]
    assert deck.boundary[0].components == ("x", "y", "z")


def test_imported_deck_runs_as_the_toml_deck(tmp_path):
    """A few steps of both decks end in the same state (boundary, wall,
    velocities and materials all in play)."""
    from sphdyn.simulation import Simulation

    _, deck = _imported_model(tmp_path)
    (tmp_path / "ref.toml").write_text(TOML)
    ref = load_deck(tmp_path / "ref.toml")
    states = []
    for d, out in ((deck, "a"), (ref, "b")):
        sim = Simulation.from_deck(d, tmp_path / out)
        sim.run(max_steps=20, progress=False)
        states.append((sim.particles.x.copy(), sim.stepper.part("solids").kin.x.copy()))
    np.testing.assert_array_equal(states[0][0], states[1][0])
    np.testing.assert_array_equal(states[0][1], states[1][1])


@pytest.mark.parametrize("form", ["fixed", "long", "include"])
def test_the_forms_of_one_deck_import_alike(tmp_path, form):
    """Fixed 8/16-character fields, long 20-character fields (``*KEYWORD
    LONG=Y``), and a deck whose nodes are an ``*INCLUDE`` and whose yield
    stress is a ``*PARAMETER``: each imports to the same deck and files as
    the free-format deck with the same (nine-digit) numbers."""
    ref_dir, dir_ = tmp_path / "ref", tmp_path / form
    ref_dir.mkdir(), dir_.mkdir()
    free = import_deck(_write(ref_dir, keyword_deck("free9")), "m-s-kg")
    other = import_deck(_write(dir_, keyword_deck(form)), "m-s-kg")
    assert other.deck == free.deck
    assert other.files.keys() == free.files.keys()
    np.testing.assert_array_equal(other.files["model_ball.csv"], free.files["model_ball.csv"])
    ma, mb = other.files["model_solids.inp"], free.files["model_solids.inp"]
    np.testing.assert_array_equal(ma.points, mb.points)
    np.testing.assert_array_equal(ma.cells[0].data, mb.cells[0].data)


def test_units_convert_every_quantity(tmp_path):
    """The same deck in mm-ms-kg (lengths /1e-3, times /1e-3, stresses
    /1e9, densities /1e-9) imports to the same SI values to round-off."""
    files = keyword_deck("free")
    path = _write(tmp_path, files)
    si = import_deck(path, "m-s-kg")
    mm = import_deck(path, "mm-ms-kg")
    # the same numbers read in other units: each quantity scales by its unit
    def value(s):
        return float(s.split()[0])
    assert value(mm.deck["run"]["t_end"]) == pytest.approx(value(si.deck["run"]["t_end"]) * 1e-3, rel=1e-15)
    steel_si, steel_mm = si.deck["material"][1], mm.deck["material"][1]
    assert value(steel_mm["E"]) == pytest.approx(value(steel_si["E"]) * 1e9, rel=1e-15)
    assert value(steel_mm["density"]) == pytest.approx(value(steel_si["density"]) * 1e9, rel=1e-15)
    np.testing.assert_allclose(mm.files["model_ball.csv"], si.files["model_ball.csv"] * 1e-3,
                               rtol=1e-15)
    v_si = value(si.deck["body"][0]["velocity"][2])
    assert value(mm.deck["body"][0]["velocity"][2]) == pytest.approx(v_si, rel=1e-15)
    # the mass is in kg in both systems, the density 1e9 larger: the spacing
    # from mass / density is 1e-3 of the m-s-kg one, as the coordinates are
    assert value(mm.deck["body"][0]["dx"]) == pytest.approx(DX * 1e-3, rel=1e-12)


def _bad(tmp_path, text: str, capsys, extra: dict | None = None) -> str:
    (tmp_path / "bad.k").write_text(textwrap.dedent(text))
    for name, t in (extra or {}).items():
        (tmp_path / name).write_text(t)
    code = main(["import", str(tmp_path / "bad.k"), "--units", "m-s-kg"])
    err = capsys.readouterr().err
    assert code == 2, err
    return err


GOOD_HEAD = """\
*KEYWORD
*NODE
       1             0.0             0.0             0.0
       2           0.002             0.0             0.0
*ELEMENT_SPH
       1       1  1.92e-5
       2       1  1.92e-5
*PART
ball
         1         1         1
*SECTION_SPH
         1       1.2
*CONTROL_TERMINATION
    1.0e-5
"""


def test_a_deck_without_end_is_refused(tmp_path, capsys):
    err = _bad(tmp_path, GOOD_HEAD + "*MAT_ELASTIC\n         1    2400.0    3.0e10       0.2\n",
               capsys)
    assert "no *END" in err and "bad.k" in err


def test_a_node_referenced_but_not_defined(tmp_path, capsys):
    text = GOOD_HEAD.replace("       2       1  1.92e-5", "       9       1  1.92e-5")
    err = _bad(tmp_path, text + "*MAT_ELASTIC\n         1    2400.0    3.0e10       0.2\n*END\n",
               capsys)
    assert "node 9" in err and "*NODE" in err


def test_a_part_without_its_section(tmp_path, capsys):
    text = GOOD_HEAD.replace("*SECTION_SPH\n         1       1.2\n", "")
    err = _bad(tmp_path, text + "*MAT_ELASTIC\n         1    2400.0    3.0e10       0.2\n*END\n",
               capsys)
    assert "line 8: *PART" in err and "*SECTION_SPH 1" in err


def test_a_material_card_that_cannot_be_read(tmp_path, capsys):
    err = _bad(tmp_path, GOOD_HEAD + "*MAT_ELASTIC\n         1    2400.0    abcdef       0.2\n*END\n",
               capsys)
    assert "line 15: *MAT_ELASTIC" in err and "cannot be read" in err


def test_a_missing_include(tmp_path, capsys):
    err = _bad(tmp_path, GOOD_HEAD + "*INCLUDE\nmissing.k\n*END\n", capsys)
    assert "line 15: *INCLUDE" in err and "missing.k" in err


def test_what_changes_the_result_stops_the_import_unless_allowed(tmp_path, capsys):
    """A keyword sphdyn does not import (here an angular body load) is
    listed; it changes the result, so the import fails with exit 2 and
    writes nothing, and with --allow-partial writes the deck listing it."""
    text = (GOOD_HEAD + "*MAT_ELASTIC\n         1    2400.0    3.0e10       0.2\n"
            "*LOAD_BODY_RX\n         1       1.0\n*END\n")
    err = _bad(tmp_path, text, capsys)
    assert "line 17: *LOAD_BODY_RX" in err and "change the result" in err
    assert not (tmp_path / "bad.toml").exists()
    code = main(["import", str(tmp_path / "bad.k"), "--units", "m-s-kg", "--allow-partial"])
    assert code == 0
    head = (tmp_path / "bad.toml").read_text().splitlines()[:3]
    assert any("LOAD_BODY_RX" in line for line in head)


def test_cscm_units_must_agree(tmp_path):
    """MAT_CSCM_CONCRETE's UNITS field names the units of FPC and DAGG: one
    that disagrees with --units is an error, not a silent factor of 1e9."""
    text = GOOD_HEAD + textwrap.dedent("""\
        *MAT_CSCM_CONCRETE
                 1    2400.0         1       0.0         0       0.0       0.0         0
               0.0
            38.0e6     0.016         4
        *END
        """)
    (tmp_path / "c.k").write_text(text)
    imp = import_deck(tmp_path / "c.k", "m-s-kg")
    m = imp.deck["material"][0]
    assert (m["model"], m["fc"], m["aggregate_size"], m["rate_effects"]) == \
        ("cscm", "38000000.0 Pa", "0.016 m", False)
    with pytest.raises(KeywordError, match="UNITS = 4"):
        import_deck(tmp_path / "c.k", "mm-ms-kg")


def test_sph_rows_all_read(tmp_path):
    """ansys-dyna-core 0.12 keeps only the first row of *ELEMENT_SPH; every
    row must arrive (scan.sph_elements)."""
    imp = import_deck(_write(tmp_path, keyword_deck("fixed")), "m-s-kg")
    assert imp.files["model_ball.csv"].shape == (box_lattice(BALL[0], BALL[1], DX, 3).shape[0], 3)


def test_run_takes_a_keyword_deck(tmp_path, capsys):
    """``sphdyn run MODEL.k --units ...`` imports into OUT/imported/ and runs
    that deck; without --units it says what to add."""
    path = _write(tmp_path, keyword_deck("free"))
    out = tmp_path / "run"
    assert main(["run", str(path), "--out", str(out), "-q", "--max-steps", "3"]) == 2
    assert "--units" in capsys.readouterr().err
    code = main(["run", str(path), "--units", "m-s-kg", "--out", str(out), "-q",
                 "--max-steps", "3"])
    assert code == 0, capsys.readouterr().err
    assert (out / "imported" / "model.toml").is_file()
    assert (out / "imported" / "model_solids.inp").is_file()
    assert (out / "summary.json").is_file()


def test_the_shipped_example_is_the_tested_deck():
    """examples/lsdyna/ball_and_plate.k (docs/lsdyna.md runs it) is the fixed
    form tested above, below its comment lines."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "lsdyna" / "ball_and_plate.k"
    lines = path.read_text().splitlines()
    body = "\n".join(line for line in lines if not line.startswith("$")) + "\n"
    assert body == keyword_deck("fixed")["model.k"]


def test_initial_velocity_of_every_node(tmp_path):
    """``*INITIAL_VELOCITY`` with NSID = 0 gives every body its velocity, and
    so does a node set holding all of a part's particles; a set holding
    some of them is listed as changing the result."""
    text = GOOD_HEAD + textwrap.dedent("""\
        *MAT_ELASTIC
                 1    2400.0    3.0e10       0.2
        *INITIAL_VELOCITY
                 0
               0.0       0.0     -15.0
        *END
        """)
    (tmp_path / "v.k").write_text(text)
    imp = import_deck(tmp_path / "v.k", "m-s-kg")
    assert imp.deck["body"][0]["velocity"] == ["0.0 m/s", "0.0 m/s", "-15.0 m/s"]
    assert not imp.dropped
    for nodes, whole in (("1,2", True), ("2", False)):
        (tmp_path / "w.k").write_text(text.replace("\n         0\n", "\n         3\n")
                                      .replace("*END", f"*SET_NODE_LIST\n3\n{nodes}\n*END"))
        imp = import_deck(tmp_path / "w.k", "m-s-kg")
        if whole:
            assert imp.deck["body"][0]["velocity"][2] == "-15.0 m/s"
            assert not imp.dropped
        else:
            assert "velocity" not in imp.deck["body"][0]
            assert [d.physics for d in imp.dropped] == [True]
            assert "line 17: *INITIAL_VELOCITY" in imp.dropped[0].line()
            assert "not the nodes of whole parts" in imp.dropped[0].line()
    (tmp_path / "x.k").write_text(text.replace("\n         0\n", "\n         3\n"))
    with pytest.raises(KeywordError, match="node set 3, which no"):
        import_deck(tmp_path / "x.k", "m-s-kg")


def test_velocity_of_a_part_set(tmp_path):
    """``*INITIAL_VELOCITY_GENERATION`` with STYP = 1 names a part set: its
    parts get the velocity (the set read in free format, which
    ansys-dyna-core cuts short); a second velocity for the same part is
    listed and the first kept."""
    text = GOOD_HEAD + textwrap.dedent("""\
        *MAT_ELASTIC
                 1    2400.0    3.0e10       0.2
        *SET_PART_LIST
        5
        9,1
        *INITIAL_VELOCITY_GENERATION
                 5         1       0.0       1.0       2.0       3.0
        *END
        """)
    (tmp_path / "p.k").write_text(text)
    imp = import_deck(tmp_path / "p.k", "m-s-kg")
    assert imp.deck["body"][0]["velocity"] == ["1.0 m/s", "2.0 m/s", "3.0 m/s"]
    assert not imp.dropped
    (tmp_path / "q.k").write_text(text.replace("*END", "*INITIAL_VELOCITY_GENERATION\n"
                                               "         1         2       0.0       "
                                               "4.0\n*END"))
    imp = import_deck(tmp_path / "q.k", "m-s-kg")
    assert imp.deck["body"][0]["velocity"][0] == "1.0 m/s"
    assert "a second initial velocity" in imp.dropped[0].line()


@pytest.mark.parametrize("name", ["m-s-kg", "mm-ms-kg", "mm-s-t", "mm-ms-g", "cm-us-g",
                                  "m-ms-kg"])
def test_each_unit_system_has_the_stress_unit_it_names(name):
    """Stress = mass / (length time^2) of the system equals the stress unit
    its help names (pint's, independent of units.py), and velocity and
    density follow from length, time and mass."""
    import pint

    from sphdyn.lsdyna.units import SYSTEMS, Units

    u = Units.named(name)
    stress_unit = SYSTEMS[name][3].split(", ")[1]
    assert u.stress == pytest.approx(pint.UnitRegistry()(stress_unit).to("Pa").magnitude,
                                     rel=1e-12)
    assert u.velocity == pytest.approx(u.length / u.time, rel=1e-15)
    assert u.density == pytest.approx(u.mass / u.length ** 3, rel=1e-15)


def test_plastic_kinematic_etan_is_the_slope_past_yield():
    """ETAN becomes j2's plastic modulus H = E Et / (E - Et): a material point
    of the imported steel pulled in uniaxial stress past yield has the
    tangent modulus ETAN (2 GPa), whatever the formula's algebra."""
    from sphdyn.materials.driver import drive

    text = GOOD_HEAD.replace("*CONTROL_TERMINATION", "*MAT_PLASTIC_KINEMATIC\n"
                             "         1    7850.0   2.0e+11       0.3   5.0e+08   2.0e+09"
                             "       1.0\n*CONTROL_TERMINATION") + "*END\n"
    m = _import_text(text)["material"][0]
    params = {k: float(v.split()[0]) if isinstance(v, str) and " " in v else v
              for k, v in m.items() if k not in ("name", "model")}
    res = drive("j2", params, "uniaxial-tension", strain=0.01, n_steps=400)
    s, e = res["stress"][:, 0], res["strain"][:, 0]
    slope = (s[-1] - s[-50]) / (e[-1] - e[-50])
    assert slope == pytest.approx(2.0e9, rel=1e-6)


def _import_text(text: str) -> dict:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        (Path(d) / "m.k").write_text(text)
        return import_deck(Path(d) / "m.k", "m-s-kg").deck


def _cscm_field_units(nc: float, nt: float) -> dict[str, str]:
    """The unit of each *MAT_CSCM field in mm-ms-kg (stress GPa, force kN),
    written out here by the parameter's dimension, independently of
    sphdyn/lsdyna/convert.py: a wrong power there fails the test."""
    units = {k: "GPa" for k in ("K", "G", "alpha", "lamda", "X0", "overc", "overt")}
    units |= {k: "1/GPa" for k in ("beta", "theta1", "beta1", "theta2", "beta2", "D1")}
    units |= {"D2": "1/GPa**2", "GFC": "kN/mm", "GFT": "kN/mm", "GFS": "kN/mm",
              "eta0c": f"ms**{1 - nc}", "eta0t": f"ms**{1 - nt}"}
    return units


def test_full_cscm_in_deck_units_is_the_same_material(tmp_path):
    """*MAT_CSCM with every parameter of sphdyn's generated set for f'c =
    43.1 MPa, dagg = 8 mm, written in mm-ms-kg (each value converted by pint
    from its dimension), imports to those SI values to round-off (1e-12:
    one product of unit factors); NH or PMOD other than 0 is listed."""
    import pint

    from sphdyn.materials.cscm.defaults import default_parameters

    si = default_parameters(43.1e6, 0.008)
    units = _cscm_field_units(si["nc"], si["nt"])
    ureg = pint.UnitRegistry()
    base = {"K": "Pa", "G": "Pa", "alpha": "Pa", "lamda": "Pa", "X0": "Pa", "overc": "Pa",
            "overt": "Pa", "D2": "1/Pa**2", "GFC": "J/m**2", "GFT": "J/m**2",
            "GFS": "J/m**2", "eta0c": f"s**{1 - si['nc']}", "eta0t": f"s**{1 - si['nt']}"}

    def deck_value(key):
        if key not in units:
            return si[key]
        unit = base.get(key, "1/Pa")
        return ureg.Quantity(si[key], unit).to(units[key]).magnitude

    cards = [["mid", 1, "ro", 2.4e-6, "nplot", 1, "incre", 0.0, "irate", 1, "erode", 1.05,
              "recov", 0.0, "itretrc", 0],
             ["G", "K", "alpha", "theta", "lamda", "beta", "NH", "CH"],
             ["alpha1", "theta1", "lamda1", "beta1", "alpha2", "theta2", "lamda2", "beta2"],
             ["R", "X0", "W", "D1", "D2"],
             ["B", "GFC", "D", "GFT", "GFS", "pwrc", "pwrt", "PMOD"],
             ["eta0c", "nc", "eta0t", "nt", "overc", "overt", "srate", "repow"]]
    rows = [",".join(repr(v) for v in cards[0][1::2]), "0.0"]  # the second card: PRED
    for card in cards[1:]:
        rows.append(",".join("0.0" if k in ("NH", "CH", "PMOD") else repr(deck_value(k))
                             for k in card))
    mm = GOOD_HEAD.replace("0.002", "2.0").replace("1.0e-5", "0.01")  # masses stay kg
    text = mm + "*MAT_CSCM\n" + "\n".join(rows) + "\n*END\n"
    (tmp_path / "c.k").write_text(text)
    imp = import_deck(tmp_path / "c.k", "mm-ms-kg")
    m = imp.deck["material"][0]
    assert not imp.dropped, [d.line() for d in imp.dropped]
    assert m["rate_effects"] is True and m["erode"] is True
    assert m["erode_strain"] == pytest.approx(0.05, rel=1e-12)
    assert float(m["density"].split()[0]) == pytest.approx(2400.0, rel=1e-12)
    for key in ("K", "G", *[k for c in cards[1:] for k in c if k not in ("NH", "CH",
                                                                          "PMOD")]):
        assert float(m[key]) == pytest.approx(si[key], rel=1e-12, abs=0.0), key
    write_import(imp, tmp_path / "c.toml")
    load_deck(tmp_path / "c.toml")  # the deck's own checks accept every value
    text = text.replace(rows[2], rows[2].rsplit(",", 2)[0] + ",2.0,0.0")  # NH = 2
    (tmp_path / "d.k").write_text(text)
    imp = import_deck(tmp_path / "d.k", "mm-ms-kg")
    assert ["NH = 2" in d.line() and d.physics for d in imp.dropped] == [True]


HEX = """\
*KEYWORD
*NODE
1,0.0,0.0,0.0
2,0.01,0.0,0.0
3,0.01,0.01,0.0
4,0.0,0.01,0.0
5,0.0,0.0,0.01
6,0.01,0.0,0.01
7,0.01,0.01,0.01
8,0.0,0.01,0.01
*ELEMENT_SOLID
1,1,1,2,3,4,5,6,7,8
*PART
cube
1,1,1
*SECTION_SOLID
1,1
*MAT_ELASTIC
1,7850.0,2.0e11,0.3
*SET_NODE_LIST
1
5,6,7,8
*SET_NODE_LIST
2
1,2,3,4
*BOUNDARY_SPC_SET
2,0,1,1,1
*CONTROL_TERMINATION
1.0e-4
"""


@pytest.mark.parametrize("vad, curve, expect", [
    (0, "0.0,2.0\n1.0,2.0", {"type": "velocity", "velocity": [0, 0, -6.0]}),
    (0, "0.0,0.0\n2.0e-5,2.0\n1.0,2.0",
     {"type": "velocity", "velocity": [0, 0, -6.0], "ramp_time": 2e-5}),
    (2, "0.0,0.0\n1.0e-4,1.0e-3",
     {"type": "displacement", "displacement": [0, 0, -3.0e-3], "ramp_time": 1e-4}),
])
def test_prescribed_motion_of_a_node_set(tmp_path, vad, curve, expect):
    """*BOUNDARY_PRESCRIBED_MOTION_SET (DOF 3, SF -3) with a constant curve
    is a velocity boundary, with a linear rise to a constant the same with
    its ramp_time, a displacement (VAD 2) a ramped displacement; the top
    nodes of the imported cube then move so (one run, the first steps)."""
    text = HEX + f"*BOUNDARY_PRESCRIBED_MOTION_SET\n1,3,{vad},9,-3.0\n" \
        f"*DEFINE_CURVE\n9\n{curve}\n*END\n"
    (tmp_path / "m.k").write_text(text)
    imp = import_deck(tmp_path / "m.k", "m-s-kg")
    assert not imp.dropped, [d.line() for d in imp.dropped]
    b = imp.deck["boundary"][1]
    assert b["components"] == ["z"] and b["type"] == expect["type"]
    kind = expect["type"]
    assert [float(c.split()[0]) for c in b[kind]] == pytest.approx(expect[kind], rel=1e-15)
    assert float(b.get("ramp_time", "0 s").split()[0]) == expect.get("ramp_time", 0.0)
    sets = {s["name"]: s for s in imp.deck["set"]}
    assert sorted(imp.files["m_solids.inp"].point_sets[sets[b["set"]]["group"]]) == [4, 5, 6, 7]
    write_import(imp, tmp_path / "m.toml")
    model = build_model(load_deck(tmp_path / "m.toml"))
    assert model is not None
    one = HEX + f"*BOUNDARY_PRESCRIBED_MOTION_NODE\n7,3,{vad},9,-3.0\n" \
        f"*DEFINE_CURVE\n9\n{curve}\n*END\n"
    (tmp_path / "n.k").write_text(one)
    imp = import_deck(tmp_path / "n.k", "m-s-kg")
    (b1,) = [b for b in imp.deck["boundary"] if b["type"] != "fixed"]
    assert {k: v for k, v in b1.items() if k != "set"} == \
        {k: v for k, v in b.items() if k != "set"}
    group = next(s["group"] for s in imp.deck["set"] if s["name"] == b1["set"])
    assert list(imp.files["n_solids.inp"].point_sets[group]) == [6]  # node 7


def test_motion_curves_that_cannot_be_carried_over_are_listed(tmp_path):
    """A curve that is neither constant nor a ramp to a constant, one that
    ends before the run, one with offsets, and a motion with a DEATH time
    are each listed as changing the result; a curve that is not defined is
    an error."""
    cases = {"0.0,0.0\n1.0e-5,2.0\n2.0e-5,0.0\n1.0,0.0": "neither constant",
             "0.0,2.0\n1.0e-5,2.0": "not the run's",
             "": "OFFA"}
    for curve, words in cases.items():
        head = "9,0,1.0,1.0,0.5\n0.0,2.0\n1.0,2.0" if not curve else f"9\n{curve}"
        text = HEX + "*BOUNDARY_PRESCRIBED_MOTION_SET\n1,3,0,9,-3.0\n" \
            f"*DEFINE_CURVE\n{head}\n*END\n"
        (tmp_path / "m.k").write_text(text)
        imp = import_deck(tmp_path / "m.k", "m-s-kg")
        assert len(imp.deck["boundary"]) == 1
        assert [words in d.line() and d.physics for d in imp.dropped] == [True], words
    text = HEX + "*BOUNDARY_PRESCRIBED_MOTION_SET\n1,3,0,9,-3.0,0,5.0e-5\n" \
        "*DEFINE_CURVE\n9\n0.0,2.0\n1.0,2.0\n*END\n"
    (tmp_path / "m.k").write_text(text)
    imp = import_deck(tmp_path / "m.k", "m-s-kg")
    assert len(imp.deck["boundary"]) == 2
    assert ["DEATH" in d.line() for d in imp.dropped] == [True]
    (tmp_path / "m.k").write_text(HEX + "*BOUNDARY_PRESCRIBED_MOTION_SET\n1,3,0,9\n*END\n")
    with pytest.raises(KeywordError, match="curve 9, which no"):
        import_deck(tmp_path / "m.k", "m-s-kg")


@pytest.mark.parametrize("units, sf, g", [("m-s-kg", "9.81", -9.81),
                                          ("mm-ms-kg", "0.00981", -9.81),
                                          ("m-s-kg", "-2.0", 2.0)])
def test_body_load_is_gravity_against_its_sign(tmp_path, units, sf, g):
    """*LOAD_BODY_Z is a base acceleration: the body force acts against a
    positive SF times the curve (LS-DYNA Keyword Manual, *LOAD_BODY:
    "positive body load acts in the negative direction"), so SF = 9.81 m/s^2
    on a constant curve of 1 is [run] gravity (0, 0, -9.81) m/s^2; a ramped
    curve is listed (sphdyn's gravity is constant) and kept at full value."""
    text = (HEX.replace("1.0e-4", "0.1" if units == "mm-ms-kg" else "1.0e-4")
            + f"*LOAD_BODY_Z\n4,{sf}\n*DEFINE_CURVE\n4\n0.0,1.0\n1000.0,1.0\n*END\n")
    (tmp_path / "g.k").write_text(text)
    imp = import_deck(tmp_path / "g.k", units)
    assert not imp.dropped
    assert [float(c.split()[0]) for c in imp.deck["run"]["gravity"]] == \
        pytest.approx([0.0, 0.0, g], rel=1e-12)
    (tmp_path / "h.k").write_text(text.replace("0.0,1.0\n1000.0", "0.0,0.0\n1.0e-5,1.0\n1000.0"))
    imp = import_deck(tmp_path / "h.k", units)
    assert ["ramps" in d.line() for d in imp.dropped] == [True]
    assert float(imp.deck["run"]["gravity"][2].split()[0]) == pytest.approx(g, rel=1e-12)


def _disc_script():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "lsdyna" / "disc_impact.py"
    spec = importlib.util.spec_from_file_location("disc_impact_example", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


#: What the disc's TOML deck sets that no keyword carries (docs/lsdyna.md)
SAME_AS_IMPORT = ["material.concrete.rate_thresholds=false"]


def test_the_papers_disc_as_a_keyword_deck(tmp_path):
    """examples/lsdyna/disc_impact.k is what its script writes, and imported
    in mm-ms-kg it is the main job: the TOML deck's particles (to the
    round-off of mm -> m, 1e-15 of the disc's size), its CSCM (1e-12), and
    with the one choice no keyword carries set as the import's (docs/
    lsdyna.md) the same state after 60 steps (15 us, into the contact with
    the base): positions to 1e-14 m and velocities to 1e-11 m/s, a few ulps
    of input grown over 60 steps (measured 1.4e-17 m and 3e-14 m/s on the
    machine that wrote this; the margin is for other processors' round-off)."""
    from pathlib import Path

    from sphdyn.simulation import Simulation

    disc = _disc_script()
    shipped = Path(disc.__file__).with_name("disc_impact.k")
    assert shipped.read_text() == disc.model_text()
    (tmp_path / "disc_impact.k").write_text(disc.model_text())
    (tmp_path / "disc_impact_particles.k").write_text(disc.particles_text())
    imp = import_deck(tmp_path / "disc_impact.k", "mm-ms-kg")
    assert not imp.dropped, [d.line() for d in imp.dropped]
    write_import(imp, tmp_path / "disc.toml")
    deck = load_deck(tmp_path / "disc.toml")
    ref = load_deck(disc.TOML, overrides=SAME_AS_IMPORT)
    a, b = build_model(deck), build_model(ref)
    np.testing.assert_allclose(a.particles.x, b.particles.x, rtol=0, atol=1e-15 * 0.1)
    np.testing.assert_array_equal(a.particles.m, b.particles.m)
    np.testing.assert_allclose(a.groups[0].params, b.groups[0].params, rtol=1e-12, atol=0)
    states = []
    for d, out in ((deck, "a"), (ref, "b")):
        sim = Simulation.from_deck(d, tmp_path / out)
        sim.run(max_steps=60, progress=False)
        states.append((sim.particles.x.copy(), sim.particles.v.copy()))
    np.testing.assert_allclose(states[0][0], states[1][0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(states[0][1], states[1][1], rtol=0, atol=1e-11)
    assert states[1][1][:, 1].max() > 0.1  # the base has pushed back


def test_every_imported_keyword_is_in_the_docs_table():
    """docs/lsdyna.md's table names each keyword the importer maps
    (convert.HANDLED), so a user can look up what becomes of it."""
    from pathlib import Path

    from sphdyn.lsdyna.convert import HANDLED

    doc = (Path(__file__).resolve().parents[1] / "docs" / "lsdyna.md").read_text()
    table = doc.split("## What is imported")[1].split("## ")[0]
    assert [k for k in HANDLED if f"`*{k}`" not in table] == []


@pytest.mark.parametrize("cards, friction, listed", [
    ("1,2,3,3\n0.3,0.3\n1.0,1.0", 0.3, []),
    ("1,2,3,3\n0.3,0.1\n1.0,1.0", 0.3, ["FD / DC / VC"]),
    ("2,1,3,3\n0.3\n1.0,1.0", None, ["side A is not every SPH part"]),
    ("1,2,3,3\n0.0\n2.0,1.0", 0.0, ["SFSA = 2"]),
])
def test_nodes_to_surface_contact_is_the_meshs_contact(tmp_path, cards, friction, listed):
    """*CONTACT_AUTOMATIC_NODES_TO_SURFACE with the SPH part on side A and the
    solid part on side B is [mesh.contact] with FS as its friction, the deck
    the same as the TOML deck with that table; what sphdyn's contact cannot
    be (another FD, a scaled stiffness, the sides swapped) is listed."""
    files = keyword_deck("free")
    files["model.k"] = files["model.k"].replace(
        "*END", f"*CONTACT_AUTOMATIC_NODES_TO_SURFACE\n{cards}\n*END")
    imp = import_deck(_write(tmp_path, files), "m-s-kg")
    assert [any(w in d.line() for w in listed) and d.physics for d in imp.dropped] == \
        [True] * len(listed)
    if friction is None:
        assert "contact" not in imp.deck["mesh"][0]
        return
    assert imp.deck["mesh"][0]["contact"] == {"friction": friction}
    write_import(imp, tmp_path / "model.toml")
    (tmp_path / "ref.toml").write_text(TOML.replace(
        "cfl = 0.6\n", f"cfl = 0.6\ncontact = {{friction = {friction}}}\n"))
    ours, ref = (load_deck(tmp_path / f).mesh[0].contact for f in ("model.toml", "ref.toml"))
    assert ours is not None and ours == ref


@pytest.mark.parametrize("cards, curve, listed", [
    ("1,7850.0,2.0e11,0.3,4.0e8,2.0e9", "", False),
    ("1,7850.0,2.0e11,0.3,1.0e8,5.0e9\n0.0,0.0,8", "0.0,4.0e8\n0.1,6.0e8", False),
    ("1,7850.0,2.0e11,0.3\n0.0,0.0,8", "0.0,4.0e8\n0.05,5.0e8\n0.1,6.0e8", False),
    ("1,7850.0,2.0e11,0.3\n0.0,0.0,8", "0.0,4.0e8\n0.05,5.0e8\n0.1,5.5e8", True),
    ("1,7850.0,2.0e11,0.3\n0.0,0.0\n0.0,0.1\n4.0e8,6.0e8", "", False),
])
def test_piecewise_linear_plasticity_is_j2(tmp_path, cards, curve, listed):
    """*MAT_PIECEWISE_LINEAR_PLASTICITY: SIGY with ETAN as the plastic
    hardening modulus, or a straight yield curve (LCSS or EPS/ES), is j2
    with yield 400 MPa and H = 2 GPa: a material point pulled past yield has
    the tangent E H / (E + H); a curve of two slopes is listed and its first
    segment kept."""
    from sphdyn.materials.driver import drive

    text = GOOD_HEAD.replace("*CONTROL_TERMINATION", f"*MAT_PIECEWISE_LINEAR_PLASTICITY\n"
                             f"{cards}\n*CONTROL_TERMINATION")
    if curve:
        text += f"*DEFINE_CURVE\n8\n{curve}\n"
    (tmp_path / "p.k").write_text(text + "*END\n")
    imp = import_deck(tmp_path / "p.k", "m-s-kg")
    assert [d.physics and "segments" in d.line() for d in imp.dropped] == [True] * listed
    m = imp.deck["material"][0]
    assert m["model"] == "j2"
    assert float(m["yield_stress"].split()[0]) == pytest.approx(4.0e8, rel=1e-12)
    assert float(m["hardening_modulus"].split()[0]) == pytest.approx(2.0e9, rel=1e-12)
    params = {k: float(v.split()[0]) if isinstance(v, str) and " " in v else v
              for k, v in m.items() if k not in ("name", "model")}
    res = drive("j2", params, "uniaxial-tension", strain=0.01, n_steps=400)
    s, e = res["stress"][:, 0], res["strain"][:, 0]
    assert (s[-1] - s[-50]) / (e[-1] - e[-50]) == pytest.approx(2e11 * 2e9 / 2.02e11,
                                                                 rel=1e-6)


HE = """\
*KEYWORD
*NODE
1,0.0,0.0,0.0
2,0.002,0.0,0.0
3,0.0,0.002,0.0
4,0.002,0.002,0.0
*ELEMENT_SPH
1,1,1.304e-5
2,1,1.304e-5
3,2,9.8e-9
4,2,9.8e-9
*PART
charge
1,1,1,1
*PART
air
2,1,2,2
*SECTION_SPH
1,1.2,0.2,2.0
*MAT_HIGH_EXPLOSIVE_BURN
1,1630.0,6930.0,2.1e10
*EOS_JWL
1,3.712e11,3.231e9,4.15,0.95,0.3,7.0e9
*MAT_NULL
2,1.225,-10.0
*EOS_LINEAR_POLYNOMIAL
2,0.0,0.0,0.0,0.0,0.4,0.4,0.0
2.5e5
*INITIAL_DETONATION
1,0.0,0.0,0.0,1.0e-6
*CONTROL_TERMINATION
1.0e-5
*END
"""


def test_explosive_and_air_with_their_eos(tmp_path):
    """*MAT_HIGH_EXPLOSIVE_BURN with *EOS_JWL (TNT's numbers) is the
    high_explosive material of preset "tnt" (the same parameter vector, to
    the bit), *MAT_NULL with *EOS_LINEAR_POLYNOMIAL (C4 = C5 = 0.4) the
    linear-polynomial gas, and *INITIAL_DETONATION a [[detonation]] of the
    charge's material at its point and time."""
    (tmp_path / "he.k").write_text(HE)
    imp = import_deck(tmp_path / "he.k", "m-s-kg")
    assert not imp.dropped, [d.line() for d in imp.dropped]
    he, air = imp.deck["material"]
    assert (he["model"], he["burn"], air["model"], air["eos"]) == \
        ("high_explosive", "both", "gas", "linear_polynomial")
    assert imp.deck["detonation"] == [{"point": ["0.0 m", "0.0 m", "0.0 m"],
                                       "time": "1e-06 s", "material": he["name"]}]
    write_import(imp, tmp_path / "he.toml")
    deck = load_deck(tmp_path / "he.toml")
    import tomli_w

    ref = dict(imp.deck, material=[
        {"name": he["name"], "model": "high_explosive", "preset": "tnt"},
        {"name": air["name"], "model": "gas", "eos": "linear_polynomial",
         "density": "1.225 kg/m^3", "C4": 0.4, "C5": 0.4, "E0": "250000.0 Pa",
         "pressure_cutoff": "-10.0 Pa"}])
    ref = tomli_w.dumps(ref)
    (tmp_path / "ref.toml").write_text(ref)
    a, b = build_model(deck), build_model(load_deck(tmp_path / "ref.toml"))
    for ga, gb in zip(a.groups, b.groups):
        np.testing.assert_array_equal(ga.params, gb.params)
    (tmp_path / "bad.k").write_text(HE.replace("*EOS_JWL\n1,", "*EOS_JWL\n7,"))
    with pytest.raises(KeywordError, match="needs an \\*EOS_JWL"):
        import_deck(tmp_path / "bad.k", "m-s-kg")


@pytest.mark.parametrize("extra, material_erosion, mesh_erosion", [
    ("*MAT_ADD_EROSION\n1,0.0\n0.0,0.0,0.0,0.3\n",
     {"principal_strain": 0.3}, {"to": "nothing"}),
    ("*MAT_ADD_EROSION\n1,-1.0,0.0,0.0,0.5\n-1.0,-1.0,-1.0,0.3\n"
     "*DEFINE_ADAPTIVE_SOLID_TO_SPH\n1,0,2,3,1,1,1\n",
     {"principal_strain": 0.3, "effective_strain": 0.5},
     {"to": "particles", "particles_per_element": 8}),
])
def test_element_erosion(tmp_path, extra, material_erosion, mesh_erosion):
    """*MAT_ADD_EROSION's MXEPS and EFFEPS are the material's principal and
    effective strain rules (0 or EXCL: no rule) and the mesh erodes its
    elements away (LS-DYNA's erosion), or into eight particles each with
    *DEFINE_ADAPTIVE_SOLID_TO_SPH NQ = 2; the deck's tables are the TOML
    deck's."""
    (tmp_path / "e.k").write_text(HEX + extra + "*END\n")
    imp = import_deck(tmp_path / "e.k", "m-s-kg")
    assert not imp.dropped, [d.line() for d in imp.dropped]
    assert imp.deck["material"][0]["erosion"] == material_erosion
    assert imp.deck["mesh"][0]["erosion"] == mesh_erosion
    write_import(imp, tmp_path / "e.toml")
    deck = load_deck(tmp_path / "e.toml")
    assert deck.mesh[0].erosion.to == mesh_erosion["to"]
    assert deck.material[0].erosion.principal_strain == 0.3
    build_model(deck)
    if "ADAPTIVE" in extra:  # the _ID form's first card is the ID (ansys-dyna-core
        # reads that card always: a plain block must not lose its first card to it)
        text = extra.replace("SOLID_TO_SPH\n", "SOLID_TO_SPH_ID\n9,debris\n")
        (tmp_path / "i.k").write_text(HEX + text + "*END\n")
        same = import_deck(tmp_path / "i.k", "m-s-kg")
        assert not same.dropped
        assert same.deck["mesh"][0]["erosion"] == imp.deck["mesh"][0]["erosion"]


def test_cscm_erode_erodes_elements_and_other_criteria_are_listed(tmp_path):
    """MAT_159's ERODE on a solid part is the damage rule of its elements; a
    *MAT_ADD_EROSION criterion sphdyn has no rule for (MXPRES) is listed, and
    adaptivity without an erosion rule is listed as eroding nothing."""
    cscm = ("*MAT_CSCM_CONCRETE\n1,2400.0,1,0.0,0,1.05,0.0,0\n0.0\n38.0e6,0.016,4\n")
    (tmp_path / "c.k").write_text(HEX.replace("*MAT_ELASTIC\n1,7850.0,2.0e11,0.3\n", cscm)
                                  + "*END\n")
    imp = import_deck(tmp_path / "c.k", "m-s-kg")
    assert imp.deck["material"][0]["erosion"] == {"erode": 1.05}
    assert imp.deck["mesh"][0]["erosion"] == {"to": "nothing"}
    (tmp_path / "d.k").write_text(HEX + "*MAT_ADD_EROSION\n1,0.0,1.0e9\n*END\n")
    imp = import_deck(tmp_path / "d.k", "m-s-kg")
    assert ["MXPRES" in d.line() for d in imp.dropped] == [True]
    assert "erosion" not in imp.deck["mesh"][0]
    (tmp_path / "f.k").write_text(HEX + "*DEFINE_ADAPTIVE_SOLID_TO_SPH\n1,0,1,3,1,1,1\n"
                                  "*END\n")
    imp = import_deck(tmp_path / "f.k", "m-s-kg")
    assert ["without an erosion rule" in d.line() for d in imp.dropped] == [True]


def test_curves_for_dynamic_relaxation(tmp_path):
    """SIDR = 1 (a curve of the dynamic-relaxation initialisation only) gives
    no motion; SIDR = 2 drives the run too, and its initialisation, which
    sphdyn does not do, is listed."""
    for sidr, boundaries, words in ((1, 1, "SIDR = 1"), (2, 2, "SIDR = 2")):
        (tmp_path / "m.k").write_text(
            HEX + "*BOUNDARY_PRESCRIBED_MOTION_SET\n1,3,0,9,-3.0\n"
            f"*DEFINE_CURVE\n9,{sidr}\n0.0,2.0\n1.0,2.0\n*END\n")
        imp = import_deck(tmp_path / "m.k", "m-s-kg")
        assert len(imp.deck["boundary"]) == boundaries
        assert [words in d.line() and d.physics for d in imp.dropped] == [True]


def test_body_loads_on_a_part_set(tmp_path):
    """*LOAD_BODY_PARTS with a set holding every part changes nothing; a set
    without the cube's part is listed (sphdyn's gravity acts on every part)."""
    for parts, listed in (("1", []), ("7", ["set 5 only"])):
        (tmp_path / "g.k").write_text(
            HEX + "*LOAD_BODY_Z\n4,9.81\n*DEFINE_CURVE\n4\n0.0,1.0\n1.0,1.0\n"
            f"*LOAD_BODY_PARTS\n5\n*SET_PART_LIST\n5\n{parts}\n*END\n")
        imp = import_deck(tmp_path / "g.k", "m-s-kg")
        assert imp.deck["run"]["gravity"][2] == "-9.81 m/s^2"
        assert [any(w in d.line() for w in listed) and d.physics
                for d in imp.dropped] == [True] * len(listed)
