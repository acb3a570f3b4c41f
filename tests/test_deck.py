"""Tests of the input-deck layer: schema, units, messages, overrides, docs."""

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import get_args, get_origin

import pytest
import tomli_w
from pydantic import BaseModel, ValidationError

from sphdyn import fields
from sphdyn.deck import (Deck, DeckError, ExistingFile, deck_to_dict,
                         dump_resolved, load_deck, loads_deck)
from sphdyn.deck import docgen, schema
from sphdyn.deck.units import DENSITY, LENGTH, PRESSURE, TIME, VELOCITY, to_si

REFERENCE = Path(__file__).resolve().parents[1] / "docs" / "deck-reference.md"

# A 2D rubber disc moving towards a rigid floor.
MINIMAL = """
[run]
dimension = 2
t_end = "1 ms"

[[material]]
name = "rubber"
model = "elastic"
density = "1.1 g/cm^3"
E = "10 MPa"
nu = 0.4

[[body]]
name = "disc"
material = "rubber"
dx = "0.5 mm"
velocity = [0, "-15 m/s"]
geometry = { shape = "cylinder", centre = [0, "6 mm"], radius = "5 mm" }

[[wall]]
name = "floor"
point = [0, 0]
normal = [0, 2]
"""

# A 3D deck using every section and every variant.
FULL = """
[run]
title = "steel ball on a concrete slab"
dimension = 3
t_end = "0.5 ms"
seed = 7

[sph]
kernel = "wendland_c2"
h_factor = 1.5
support_scale = 1.1
correction = true
xsph = 0.1
viscosity = { alpha = 0.5, beta = 1.0 }
smoothing_length = { mode = "benz", min_factor = 0.4, max_factor = 3 }
neighbours = { skin_factor = 0.3 }
cfl = 0.25

[time]
dt_max = "1 us"
collapse_ratio = 1e-3

[domain]
lo = ["-1 m", "-1 m", "-1 m"]
hi = [1, 1, 1]
margin = 0.5

[[material]]
name = "concrete"
model = "elastic"
density = "2400 kg/m^3"
K = "20 GPa"
G = "15 GPa"

[[material]]
name = "steel"
model = "j2"
density = 7850
E = "210 GPa"
nu = 0.3
yield_stress = "355 MPa"
hardening_modulus = "1 GPa"

[[body]]
name = "slab"
material = "concrete"
dx = "5 mm"
geometry = { shape = "box", lo = [-0.2, -0.2, -0.1], hi = [0.2, 0.2, 0] }

[[body]]
name = "ball"
material = "steel"
dx = "2 mm"
velocity = [0, 0, "-100 m/s"]
geometry = { shape = "sphere", centre = [0, 0, "30 mm"], radius = "20 mm" }

[[body]]
name = "pipe"
material = "steel"
dx = "2 mm"
geometry = { shape = "ring", centre = [0.5, 0, 0], inner_radius = "10 mm", outer_radius = "12 mm", length = "0.1 m", axis = "x" }

[[body]]
name = "rod"
material = "steel"
dx = "2 mm"
geometry = { shape = "cylinder", centre = [-0.5, 0, 0], radius = "5 mm", length = "50 mm", axis = "y" }

[[wall]]
name = "ground"
point = [0, 0, "-0.1 m"]
normal = [0, 0, 1]
stiffness = "bulk"
alpha = 0.2
bulk_modulus = "30 GPa"
friction = 0.3
thickness_factor = 0.6

[[set]]
name = "edges"
body = "slab"
region = { shape = "halfspace", point = [0.19, 0, 0], normal = [3, 0, 4] }

[[set]]
name = "corner"
region = { shape = "box", lo = [0.1, 0.1, -0.1], hi = [0.2, 0.2, 0] }

[[set]]
name = "core"
body = "ball"
region = { shape = "sphere", centre = [0, 0, 0.03], radius = 0.005 }

[[set]]
name = "axis"
region = { shape = "cylinder", centre = [0, 0, 0], radius = 0.01, axis = "z" }

[[set]]
name = "everything"

[[boundary]]
set = "edges"
type = "fixed"

[[boundary]]
set = "axis"
type = "velocity"
velocity = [0, 0, "-1 m/s"]

[output]
every = "10 us"
vtk = false
fields = ["velocity", "stress", "plastic_strain", "bc"]
history_every = 5
checkpoint_every = 1000
progress = false
"""


def edited(text, edit):
    """Return ``text`` with ``edit(data)`` applied to its parsed TOML."""
    data = tomllib.loads(text)
    edit(data)
    return tomli_w.dumps(data)


def problems_of(text, overrides=None):
    with pytest.raises(DeckError) as info:
        loads_deck(text, overrides=overrides)
    assert str(info.value) == "\n".join(info.value.problems)
    return info.value.problems


LINE = re.compile(r"^\S.*?: .+\. Fix: .+$")


def line_for(problems, path):
    """The problem line for ``path``, checked for the required shape."""
    lines = [p for p in problems if p.startswith(path + ":")]
    assert lines, f"no problem for {path!r} in {problems}"
    assert LINE.match(lines[0]), lines[0]
    return lines[0]


# --------------------------------------------------------------------------
# Valid decks
# --------------------------------------------------------------------------

def test_minimal_deck_is_converted_to_si_with_defaults():
    deck = loads_deck(MINIMAL)
    assert deck.run.dimension == 2
    assert deck.run.t_end == pytest.approx(1e-3)
    rubber = deck.material[0]
    assert rubber.density == pytest.approx(1100.0)
    assert rubber.E == pytest.approx(1e7)
    disc = deck.body[0]
    assert disc.dx == pytest.approx(5e-4)
    assert disc.velocity == (0.0, -15.0, 0.0)       # padded with z = 0
    assert disc.geometry.centre == pytest.approx((0.0, 6e-3, 0.0))
    assert disc.geometry.length is None and disc.geometry.axis == "z"
    assert deck.wall[0].normal == (0.0, 1.0, 0.0)   # normalised
    # defaults
    assert deck.sph.kernel == "cubic_spline" and deck.sph.h_factor == 1.2
    assert deck.sph.viscosity.alpha == 1.0 and deck.sph.viscosity.beta == 2.0
    assert deck.sph.cfl == 0.3 and deck.time.dt_max is None
    assert deck.wall[0].stiffness == "mass" and deck.wall[0].alpha == 0.1
    # Autodyn's SPH density factors; not parameters of the model
    assert (rubber.min_density_factor, rubber.max_density_factor) == (0.2, 3.0)
    assert "min_density_factor" not in rubber.values()
    assert "max_density_factor" not in rubber.values()
    assert deck.set == () and deck.boundary == ()
    assert deck.output.every is None
    assert deck.frame_interval() == pytest.approx(1e-3 / 50)


def test_full_deck():
    deck = loads_deck(FULL)
    assert deck.sph.smoothing_length.mode == "benz"
    assert deck.sph.smoothing_length.max_factor == 3.0
    assert deck.time.dt_max == pytest.approx(1e-6)
    assert deck.domain.lo == (-1.0, -1.0, -1.0)
    concrete, steel = deck.material
    assert concrete.model == "elastic" and steel.model == "j2"
    assert steel.yield_stress == pytest.approx(3.55e8)
    assert [b.geometry.shape for b in deck.body] == ["box", "sphere", "ring",
                                                      "cylinder"]
    assert deck.body[2].geometry.outer_radius == pytest.approx(0.012)
    assert deck.wall[0].bulk_modulus == pytest.approx(3e10)
    assert deck.set[0].region.normal == pytest.approx((0.6, 0.0, 0.8))
    assert deck.set[3].region.length is None
    assert deck.set[4].region is None and deck.set[4].body is None
    assert deck.boundary[1].velocity == (0.0, 0.0, -1.0)
    assert deck.output.fields == ("velocity", "stress", "plastic_strain",
                                  "bc")
    assert deck.frame_interval() == pytest.approx(1e-5)


def test_elastic_constants_both_ways():
    deck = loads_deck(FULL)
    concrete, steel = deck.material
    assert concrete.bulk_modulus() == 2e10 and concrete.shear_modulus() == 1.5e10
    assert steel.bulk_modulus() == pytest.approx(210e9 / (3 * (1 - 0.6)))
    assert steel.shear_modulus() == pytest.approx(210e9 / 2.6)


@pytest.mark.parametrize("text, dim, expected", [
    ("0.5 mm", LENGTH, 5e-4),
    ("43.1 MPa", PRESSURE, 4.31e7),
    ("1 ms", TIME, 1e-3),
    ("2.4 g/cm^3", DENSITY, 2400.0),
    ("2400 kg/m^3", DENSITY, 2400.0),
    ("15 m/s", VELOCITY, 15.0),
    ("54 km/h", VELOCITY, 15.0),
    (0.25, LENGTH, 0.25),
    (3, PRESSURE, 3.0),
])
def test_unit_conversion(text, dim, expected):
    assert to_si(text, dim) == pytest.approx(expected, rel=1e-14)


def test_deck_is_frozen():
    deck = loads_deck(MINIMAL)
    with pytest.raises(ValidationError):
        deck.run.t_end = 2.0
    with pytest.raises(ValidationError):
        deck.body = ()
    with pytest.raises(TypeError):
        deck.body[0].velocity[0] = 1.0  # vectors are tuples


def test_dump_resolved_round_trip(tmp_path):
    deck = loads_deck(FULL)
    path = tmp_path / "resolved.toml"
    dump_resolved(deck, path)
    again = load_deck(path)
    assert again == deck
    data = tomllib.loads(path.read_text())
    assert data["sph"]["viscosity"]["beta"] == 1.0          # defaults written
    assert data["material"][1]["E"] == 210e9               # SI floats
    assert "dt_max" in data["time"] and "every" in data["output"]
    assert "length" not in data["set"][3]["region"]         # None omitted
    assert data == deck_to_dict(deck)


SHIPPED_DECKS = sorted([*(Path(__file__).parents[1] / "examples").glob("*.toml"),
                        *(Path(__file__).parents[1] / "validation" / "cases").glob("*.toml")])


@pytest.mark.parametrize("path", SHIPPED_DECKS, ids=lambda p: p.stem)
def test_shipped_decks_resolve_and_load_again(path, tmp_path):
    """A restart reads deck.resolved.toml (every default written out): a rule
    that looks at which keys the user wrote, rather than their values, would
    refuse it (the non-reflecting boundary's components did, 2026-11-30)."""
    deck = load_deck(path)
    dump_resolved(deck, tmp_path / "deck.resolved.toml")
    assert load_deck(tmp_path / "deck.resolved.toml") == deck


RESOLVED_EXTRAS = """
[run]
dimension = 3
t_end = "1 us"
[[material]]
name = "steel"
model = "elastic"
density = "7850 kg/m^3"
E = "210 GPa"
nu = 0.3
[[mesh]]
name = "plate"
material = "steel"
[mesh.block]
lo = [0, 0, 0]
hi = ["10 mm", "10 mm", "10 mm"]
divisions = [2, 2, 2]
[[set]]
name = "back"
mesh = "plate"
region = { shape = "box", lo = [-1, -1, -1], hi = [1, 1, "0.1 mm"] }
[[set]]
name = "all"
mesh = "plate"
region = { shape = "halfspace", point = [0, 0, -1], normal = [0, 0, 1] }
[[boundary]]
set = "back"
type = "non_reflecting"
[[probe]]
set = "all"
"""


def test_resolved_deck_with_mesh_defaults_builds(tmp_path):
    """The defaults whose meaning depends on the set's kind (a mesh probe's
    quantities, the non-reflecting boundary's directions) mean the same once
    written out: the resolved deck builds the same model."""
    from sphdyn.build.model import build_model

    deck = loads_deck(RESOLVED_EXTRAS)
    dump_resolved(deck, tmp_path / "r.toml")
    again = load_deck(tmp_path / "r.toml")
    names = [build_model(d).probes[0].quantities for d in (deck, again)]
    assert names[0] == names[1] and "von_mises" not in names[0]


def test_dump_resolved_round_trip_minimal(tmp_path):
    deck = loads_deck(MINIMAL)
    dump_resolved(deck, tmp_path / "r.toml")
    assert load_deck(tmp_path / "r.toml") == deck


# --------------------------------------------------------------------------
# Errors: each names the path and says how to fix it
# --------------------------------------------------------------------------

def _set(path, value):
    """An edit setting ``data[path...] = value``."""
    def edit(data):
        node = data
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return edit


def _delete(*path):
    def edit(data):
        node = data
        for key in path[:-1]:
            node = node[key]
        del node[path[-1]]
    return edit


def _boundary(table):
    """An edit adding a set "all" and the boundary ``table`` on it."""
    def edit(data):
        data["set"] = [{"name": "all"}]
        data["boundary"] = [table]
    return edit


ERROR_CASES = [
    # unknown keys, with the nearest valid key
    (_set(["body", 0, "geometry", "radus"], 0.1), "body[0].geometry.radus",
     ["unknown key", "did you mean 'radius'"]),
    (_set(["run", "t_ned"], 1.0), "run.t_ned", ["did you mean 't_end'"]),
    (_set(["sph"], {"kernal": "gaussian"}), "sph.kernal",
     ["did you mean 'kernel'"]),
    (_set(["bodies"], []), "bodies", ["did you mean 'body'"]),
    # wrong types
    (_set(["run", "seed"], 1.5), "run.seed", ["not an integer"]),
    (_set(["sph"], {"correction": 1}), "sph.correction", ["true or false"]),
    (_set(["sph"], {"h_factor": "big"}), "sph.h_factor", ["not a number"]),
    (_set(["run", "title"], 3), "run.title", ["not text"]),
    (_set(["body", 0, "velocity"], 5), "body[0].velocity", ["not a vector"]),
    (_set(["run"], 5), "run", ["not a table"]),
    (_set(["sph"], {"kernel": "cubic"}), "sph.kernel",
     ["'cubic' is not allowed", "did you mean 'cubic_spline'"]),
    (_set(["material", 0, "model"], "elastc"), "material[0]",
     ["model = 'elastc' is not known", "did you mean 'elastic'"]),
    (_delete("material", 0, "model"), "material[0]",
     ["'model' is missing"]),
    # out of range
    (_set(["material", 0, "nu"], 0.6), "material[0].nu",
     ["0.6 is out of range (-1, 0.5)", "Fix: give a Poisson ratio below 0.5."]),
    (_set(["material", 0, "min_density_factor"], 1.0), "material[0].min_density_factor",
     ["out of range [0, 1)"]),
    (_set(["material", 0, "max_density_factor"], 0.9), "material[0].max_density_factor",
     ["out of range (1, inf)"]),
    (_set(["sph"], {"cfl": 0}), "sph.cfl", ["out of range (0, 1]"]),
    (_set(["body", 0, "dx"], -1e-3), "body[0].dx",
     ["out of range (0, inf)", "above 0"]),
    (_set(["output"], {"history_every": 0}), "output.history_every",
     ["at least 1"]),
    (_set(["sph"], {"cfl": math.nan}), "sph.cfl", ["not finite"]),
    # wrong unit dimension
    (_set(["body", 0, "dx"], "3 MPa"), "body[0].dx",
     ["'3 MPa' is not a length",
      "Fix: give a length such as '0.5 mm' or 0.0005 (metres)."]),
    (_set(["run", "t_end"], "5 m"), "run.t_end", ["is not a time", "'1 ms'"]),
    (_set(["material", 0, "E"], "10 blorbs"), "material[0].E",
     ["cannot be read"]),
    (_set(["material", 0, "E"], "10"), "material[0].E", ["has no unit"]),
    (_set(["body", 0, "velocity"], ["1 mm", 0]), "body[0].velocity[0]",
     ["is not a velocity"]),
    # missing required keys and sections
    (_delete("run", "t_end"), "run.t_end", ["missing", "t_end = \"1 ms\""]),
    (_delete("run", "dimension"), "run.dimension", ["missing"]),
    (_delete("material"), "material", ["missing", "[[material]]"]),
    (_set(["body"], []), "body", ["no [[body]] table"]),
    (_delete("body", 0, "geometry", "radius"), "body[0].geometry.radius",
     ["missing"]),
    # cross references and names
    (_set(["body", 0, "material"], "rubbr"), "body[0].material",
     ["no material named 'rubbr'", "did you mean 'rubber'"]),
    (_set(["set"], [{"name": "s", "body": "dsic"}]), "set[0].body",
     ["no body named 'dsic'"]),
    (_set(["boundary"], [{"set": "top", "type": "fixed"}]), "boundary[0].set",
     ["no set named 'top'", "[[set]]"]),
    (lambda d: d["wall"].append(dict(d["wall"][0])), "wall[1].name",
     ["'floor' is used by 2", "different name"]),
    (_set(["body", 0, "name"], " "), "body[0].name", ["empty"]),
    (_set(["wall", 0, "name"], "4 mm/K"), "wall[0].name", ["has a slash", "'_'"]),
    # elastic constants
    (_set(["material", 0, "K"], 1e9), "material[0]",
     ["mix", "either E and nu, or K and G, not both"]),
    (lambda d: [d["material"][0].pop(k) for k in ("E", "nu")], "material[0]",
     ["no elastic constants", "either E and nu, or K and G"]),
    (_delete("material", 0, "nu"), "material[0]",
     ["E is given without nu", "add nu"]),
    # boundaries
    (_boundary({"set": "all", "type": "fixed", "velocity": [0, 0]}),
     "boundary[0].velocity", ["takes no velocity", "remove velocity"]),
    (_boundary({"set": "all", "type": "velocity"}),
     "boundary[0].velocity", ["needs a velocity"]),
    # 2D rules
    (_set(["body", 0, "velocity"], [0, -15, 1]), "body[0].velocity",
     ["z-component is 1", "2D"]),
    (_set(["wall", 0, "normal"], [0, 1, 0.1]), "wall[0].normal",
     ["z-component"]),
    (_set(["body", 0, "geometry", "axis"], "x"), "body[0].geometry.axis",
     ["not allowed in 2D"]),
    # vectors and shapes
    (_set(["body", 0, "velocity"], [0, 1, 0, 0]), "body[0].velocity",
     ["4 entries", "3 entries"]),
    (_set(["wall", 0, "normal"], [0, 0]), "wall[0].normal", ["zero vector"]),
    (_set(["body", 0, "geometry"], {"shape": "box", "lo": [0, 0],
                                    "hi": [1, -1]}),
     "body[0].geometry.hi", ["is not above lo"]),
    (_set(["body", 0, "geometry"], {"shape": "ring", "centre": [0, 0],
                                    "inner_radius": 2, "outer_radius": 1}),
     "body[0].geometry.outer_radius", ["not greater than inner_radius"]),
    (_set(["domain"], {"lo": [1, 1], "hi": [0, 2]}), "domain.hi",
     ["is not above lo"]),
    (_set(["body", 0, "geometry", "shape"], "cone"), "body[0].geometry",
     ["shape = 'cone' is not known"]),
    # walls and output
    (_set(["wall", 0, "bulk_modulus"], 1e9), "wall[0].bulk_modulus",
     ["not used with stiffness"]),
    (_set(["output"], {"fields": ["vonmises"]}), "output.fields[0]",
     ["did you mean 'von_mises'"]),
]


@pytest.mark.parametrize("edit, path, fragments", ERROR_CASES,
                         ids=[c[1] + "-" + str(i)
                              for i, c in enumerate(ERROR_CASES)])
def test_error_names_path_and_fix(edit, path, fragments):
    problems = problems_of(edited(MINIMAL, edit))
    line = line_for(problems, path)
    for fragment in fragments:
        assert fragment in line, line
    for other in problems:
        assert LINE.match(other), other


def test_2d_selection_box_may_span_z():
    def region(lo, hi):
        def edit(data):
            data["set"] = [{"name": "s", "region": {"shape": "box", "lo": lo,
                                                    "hi": hi}}]
        return edit
    deck = loads_deck(edited(MINIMAL, region([-1, -1, -1], [1, 1, 1])))
    assert deck.set[0].region.lo == (-1.0, -1.0, -1.0)
    problems = problems_of(edited(MINIMAL, region([-1, -1, 1], [1, 1, 2])))
    assert "does not contain the plane z = 0" in line_for(problems,
                                                          "set[0].region.hi")


def test_flat_box_in_3d_is_rejected():
    def flat(data):
        data["run"]["dimension"] = 3
        data["domain"] = {"lo": [0, 0, 0], "hi": [1, 1, 0]}
    problems = problems_of(edited(MINIMAL, flat))
    assert "first 3 entries" in line_for(problems, "domain.hi")


def test_deck_error_pickles():
    import pickle
    err = pickle.loads(pickle.dumps(DeckError(["a: b. Fix: c."])))
    assert err.problems == ["a: b. Fix: c."] and str(err) == "a: b. Fix: c."


def test_table_names_label_the_problem():
    problems = problems_of(edited(MINIMAL,
                                  _set(["material", 0, "nu"], 0.6)))
    assert "in material 'rubber'" in line_for(problems, "material[0].nu")


def test_3d_rules():
    text = edited(MINIMAL, lambda d: d["run"].__setitem__("dimension", 3))
    problems = problems_of(text)
    assert "3 entries" in line_for(problems, "body[0].velocity")
    assert "needs a length" in line_for(problems, "body[0].geometry.length")
    line_for(problems, "body[0].geometry.centre")
    line_for(problems, "wall[0].point")
    line_for(problems, "wall[0].normal")
    assert len(problems) == 5


def test_all_problems_reported_together():
    def many(data):
        data["run"]["t_end"] = "3 kg"
        data["material"][0]["nu"] = 0.7
        data["body"][0]["material"] = "steel"
        data["body"][0]["colour"] = "red"
        data["wall"][0]["normal"] = [0, 0]
    problems = problems_of(edited(MINIMAL, many))
    paths = [p.split(":")[0] for p in problems]
    assert paths == ["run.t_end", "material[0].nu", "body[0].material",
                     "body[0].colour", "wall[0].normal"]


def test_type_error_does_not_hide_reference_errors():
    def both(data):
        data["material"][0]["E"] = "hard"
        data["body"][0]["material"] = "steel"
    problems = problems_of(edited(MINIMAL, both))
    line_for(problems, "material[0].E")
    line_for(problems, "body[0].material")


# --------------------------------------------------------------------------
# Overrides, files, syntax
# --------------------------------------------------------------------------

def test_overrides_are_applied_before_validation():
    deck = loads_deck(MINIMAL, overrides=[
        "sph.cfl=0.2",                        # TOML number
        "material.rubber.E=20 MPa",           # by name; not TOML -> string
        "body.0.velocity=[1, 2]",             # by index; TOML array
        "sph.viscosity.alpha=0.5",            # creates missing tables
        "run.title=drop test",
        'output.fields=["velocity"]',
        "output.vtk=false",
    ])
    assert deck.sph.cfl == 0.2
    assert deck.material[0].E == pytest.approx(2e7)
    assert deck.body[0].velocity == (1.0, 2.0, 0.0)
    assert deck.sph.viscosity.alpha == 0.5
    assert deck.run.title == "drop test"
    assert deck.output.fields == ("velocity",) and deck.output.vtk is False


@pytest.mark.parametrize("override, path, fragment", [
    ("material.rubbr.E=1", "material.rubbr.E", "did you mean 'rubber'"),
    ("material.3.E=1", "material.3.E", "index 3 is out of range"),
    ("sph.cfl", "sph.cfl", "key=value"),
    ("=3", "=3", "key=value"),
    ("run.t_end.x=1", "run.t_end.x", "not a table"),
    ("run.t_end.x.y=1", "run.t_end.x.y", "not a table"),
    ("wall.0.point.7=1", "wall.0.point.7", "out of range"),
    ("set.0.name=a", "set.0.name", "no [[set]] tables"),
    ("sph.cfll=0.2", "sph.cfll", "did you mean 'cfl'"),
    ("sph.cfl=2", "sph.cfl", "out of range"),
])
def test_bad_override(override, path, fragment):
    problems = problems_of(MINIMAL, overrides=[override])
    assert fragment in line_for(problems, path)


@pytest.mark.parametrize("override, path, fix", [
    ("time.cfl=0.2", "time.cfl", "write it as [sph] cfl"),
    ("sph.hourglass=10", "sph.hourglass", "write it as hourglass_coefficient"),
])
def test_a_moved_key_is_refused_naming_where_it_went(override, path, fix):
    # one meaning per name: [time] cfl went to [sph] (each part kind has its
    # own factor on its stable step), [sph] hourglass became
    # hourglass_coefficient ([[mesh]] hourglass names the control's form)
    line = line_for(problems_of(MINIMAL, overrides=[override]), path)
    assert "the key moved" in line and fix in line


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(DeckError) as info:
        load_deck(missing)
    assert len(info.value.problems) == 1
    assert line_for(info.value.problems, str(missing))
    assert "does not exist" in str(info.value)


def test_toml_syntax_error(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[run]\ndimension = 2\nt_end = 1 ms\n")
    with pytest.raises(DeckError) as info:
        load_deck(path)
    line = line_for(info.value.problems, str(path))
    assert "TOML syntax error" in line
    assert "line 3" in line and "column" in line


def test_load_deck_reads_file(tmp_path):
    path = tmp_path / "deck.toml"
    path.write_text(MINIMAL)
    assert load_deck(path, overrides=["run.seed=3"]).run.seed == 3


def test_existing_file_is_relative_to_deck_dir(tmp_path):
    class Uses(BaseModel):
        mesh: ExistingFile

    (tmp_path / "part.vtu").write_text("x")
    found = Uses.model_validate({"mesh": "part.vtu"},
                                context={"base_dir": tmp_path})
    assert found.mesh == (tmp_path / "part.vtu").resolve()
    with pytest.raises(ValidationError, match="does not exist.*Fix:"):
        Uses.model_validate({"mesh": "other.vtu"},
                            context={"base_dir": tmp_path})


def test_allowed_fields_can_be_extended(monkeypatch):
    text = edited(MINIMAL, _set(["output"], {"fields": ["strain_rate"]}))
    problems_of(text)
    monkeypatch.setattr(fields, "FIELDS", dict(fields.FIELDS))
    fields.register_field(fields.OutputField(
        "strain_rate", "scalar", "1/s", "Strain rate.", lambda p, c: p.rho))
    assert loads_deck(text).output.fields == ("strain_rate",)


def test_pint_is_imported_lazily():
    code = "import sys, sphdyn.deck; print('pint' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True,
                         text=True, check=True).stdout
    assert out.strip() == "False"


# --------------------------------------------------------------------------
# Generated documentation
# --------------------------------------------------------------------------

def _models(model, seen):
    """All deck models reachable from ``model``."""
    if model in seen:
        return seen
    seen.append(model)
    for info in model.model_fields.values():
        core = schema.strip_optional(schema.field_annotation(info))
        if get_origin(core) is tuple:
            core = schema.strip_optional(get_args(core)[0])
        for sub in list(schema.variants(core).values()) + [core]:
            if isinstance(sub, type) and issubclass(sub, BaseModel):
                _models(sub, seen)
    return seen


def test_every_field_has_a_description():
    models = _models(Deck, [])
    assert len(models) >= 20
    missing = [f"{m.__name__}.{k}" for m in models
               for k, info in m.model_fields.items() if not info.description]
    assert missing == []


def test_reference_is_up_to_date():
    assert REFERENCE.read_text(encoding="utf-8") == docgen.generate(), (
        "docs/deck-reference.md is stale: run python -m sphdyn.deck.docgen")


def test_reference_documents_every_key():
    text = docgen.generate()
    for model in _models(Deck, []):
        for key in model.model_fields:
            assert f"| `{key}` |" in text


def test_reference_example_is_valid():
    deck = loads_deck(docgen.EXAMPLE)
    assert deck.body[0].velocity == (0.0, -15.0, 0.0)
    assert docgen.EXAMPLE in docgen.generate()


def test_docgen_main_writes_file(tmp_path):
    out = tmp_path / "ref.md"
    assert docgen.main([str(out)]) == 0
    assert out.read_text(encoding="utf-8") == docgen.generate()


def test_probe_quantity_is_checked_and_names_the_field():
    text = MINIMAL + '[[set]]\nname = "s"\n[[probe]]\nset = "s"\nquantities = ["velocity_w"]\n'
    with pytest.raises(DeckError) as err:
        loads_deck(text)
    assert "probe[0].quantities" in str(err.value) and "Fix:" in str(err.value)
    ok = loads_deck(MINIMAL + '[[set]]\nname = "s"\n[[probe]]\nset = "s"\n')
    assert ok.probe[0].reduce == "mean" and "velocity_x" in ok.probe[0].quantities


@pytest.mark.parametrize("kind, plural", [
    ("quantity", "quantities"), ("number", "numbers"),
    ("list of quantities", "lists of quantities"),
    ("vector of quantity", "vectors of quantity")])
def test_type_names_in_the_reference_are_plural_english(kind, plural):
    """The reference's type column: a list's element type is pluralised on its
    head noun (it once printed "list of list of quantityss")."""
    assert docgen.plural(kind) == plural
    text = docgen.generate()
    assert "list of lists of quantities" in text
    assert not re.search(r"quantit(?:yss|ys)\b|numberss|vectorss|lists of list\b", text)
