"""Materials of different model families in one part: the history layout.

Each model sees its own history columns from 0 (the kernels index them by
position); :func:`sphdyn.materials.history_layout` lays the models' columns
side by side in the part's one array. Reinforced concrete needs it: CSCM
concrete particles beside J2 steel particles (the sublayer), CSCM elements
beside J2 bars.
"""

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import loads_deck
from sphdyn.fields import history_column
from sphdyn.materials import MaterialModel, get_model, history_layout


def _fake(*names):
    return MaterialModel(name="x", history_names=tuple(names), pack=None, update=None)


def test_layout_puts_the_longest_first_shares_a_family_and_appends_the_rest():
    cscm, j2, elastic = get_model("cscm"), get_model("j2"), get_model("elastic")
    names, first = history_layout([j2, elastic, cscm])
    assert names == list(cscm.history_names) + ["plastic_strain"]
    assert first[cscm.history_names] == 0
    assert first[j2.history_names] == len(cscm.history_names)
    assert first[()] == 0
    # a list that starts the columns so far shares them (one family)
    names, first = history_layout([_fake("a"), _fake("a", "b"), _fake("c")])
    assert names == ["a", "b", "c"] and first == {("a", "b"): 0, ("a",): 0, ("c",): 2}
    # a run further on shares too: j2's plastic strain is the uniaxial bar's
    # first column, behind CSCM's
    from sphdyn.materials.uniaxial import UNIAXIAL
    names, first = history_layout([j2, cscm, UNIAXIAL])
    n = len(cscm.history_names)
    assert names == list(cscm.history_names) + list(UNIAXIAL.history_names)
    assert first[UNIAXIAL.history_names] == first[j2.history_names] == n
    # one name in two places cannot be found by name: refused
    with pytest.raises(ValueError, match=r"\['b'\] of two material models"):
        history_layout([_fake("a", "b"), _fake("b", "c")])


DECK = """
[run]
dimension = 3
t_end = "40 us"
[time]
dt_max = "0.2 us"
{materials}{bodies}
[output]
every = "40 us"
progress = false
vtk = false
"""
MATERIALS = {"concrete": """
[[material]]
name = "concrete"
model = "cscm"
density = 2400.0
fc = "30 MPa"
aggregate_size = "8 mm"
""", "steel": """
[[material]]
name = "steel"
model = "j2"
density = 7850.0
E = "200 GPa"
nu = 0.3
yield_stress = "550 MPa"
hardening_modulus = "1 GPa"
"""}


def _body(name, material, y):
    """A 40 x 20 x 20 mm block at height y [mm], its x = 0 end held, its other
    end moved 0.2 mm along x over 20 us (0.5 % strain, past the steel's yield
    of 0.275 % and the concrete's tensile strength)."""
    return f"""
[[body]]
name = "{name}"
material = "{material}"
dx = "5 mm"
geometry = {{ shape = "box", lo = [0, "{y} mm", 0], hi = ["40 mm", "{y + 20} mm", "20 mm"] }}
[[set]]
name = "{name}_held"
body = "{name}"
region = {{ shape = "box", lo = [-1, -1, -1], hi = ["5 mm", 1, 1] }}
[[set]]
name = "{name}_pulled"
body = "{name}"
region = {{ shape = "box", lo = ["35 mm", -1, -1], hi = [1, 1, 1] }}
[[boundary]]
set = "{name}_held"
type = "fixed"
[[boundary]]
set = "{name}_pulled"
type = "displacement"
displacement = ["0.2 mm", 0, 0]
ramp_time = "20 us"
"""


def _run(*bodies):
    deck = loads_deck(DECK.format(materials="".join(MATERIALS[b[1]] for b in bodies),
                                  bodies="".join(_body(*b) for b in bodies)))
    s = build_stepper(deck)
    while s.t < deck.run.t_end * (1 - 1e-9):
        s.step(deck.run.t_end)
    return s.parts[0].p


def test_concrete_and_steel_particles_in_one_part_match_their_runs_alone():
    """A CSCM block and a J2 block (120 mm apart, beyond each other's supports)
    stretched in one run give the same stress and history as each block
    alone (one material in the deck, its columns from 0) at the same fixed
    step: each kernel works on its own columns (the steel's plastic strain in
    the column after CSCM's), the other columns of its rows stay at zero. The
    steel has yielded and the concrete's state moved, so a wrong column would
    show at O(1). Tolerance 1e-13 of each array's largest value: the force
    pass's slabs span the whole part (parts/sph/colouring.py), so with the
    other block present the particles' sums are added in another order
    (round-off, 2e-15 seen); the columns left at zero are compared exactly."""
    both = _run(("concrete", "concrete", 0), ("steel", "steel", 120))
    alone_c = _run(("concrete", "concrete", 0))
    alone_s = _run(("steel", "steel", 120))
    cscm = get_model("cscm").history_names
    nc = alone_c.n
    assert both.hist_names == list(cscm) + ["plastic_strain"]

    def same(a, b):
        return np.abs(a - b).max() <= 1e-13 * np.abs(b).max()

    assert same(both.sig[:nc], alone_c.sig)
    assert same(both.sig[nc:], alone_s.sig)
    assert same(both.hist[:nc, :len(cscm)], alone_c.hist)
    assert same(both.hist[nc:, len(cscm)], alone_s.hist[:, 0])
    assert np.all(both.hist[:nc, len(cscm)] == 0.0) and np.all(both.hist[nc:, :len(cscm)] == 0.0)
    eps_p = history_column(both, "plastic_strain")[nc:]
    assert eps_p.max() > 1e-3
    assert history_column(both, "kappa")[:nc].min() > 0.0


def test_one_mesh_of_concrete_and_steel_elements_lays_their_histories_side_by_side(tmp_path):
    """Elements of a CSCM group and a J2 group in one mesh (an Abaqus file's
    element sets): the points' history holds CSCM's columns then the plastic
    strain; each group starts from its own initial history in its own
    columns (CSCM's cap position kappa0 > 0; zero elsewhere) and the bar runs."""
    from test_mesh_decks import BAR, _abaqus

    _abaqus(tmp_path / "bar.inp", groups=True)
    source = ('file = "bar.inp"\n[[mesh.group]]\nname = "LEFT"\nmaterial = "concrete"\n'
              '[[mesh.group]]\nname = "RIGHT"\nmaterial = "steel"')
    text = BAR.format(t_end="1 ms", every="1 ms", damping="5000 1/s", extra="",
                      source=source, materials=MATERIALS["concrete"] + MATERIALS["steel"])
    s = build_stepper(loads_deck(text, base_dir=tmp_path))
    part = s.part("bar")
    cscm = get_model("cscm")
    assert part.pts.hist_names == list(cscm.history_names) + ["plastic_strain"]
    columns = {g.model.name: g.column for g in part.groups}
    assert columns == {"cscm": 0, "j2": len(cscm.history_names)}
    concrete = next(g for g in part.groups if g.model.name == "cscm").idx
    steel = next(g for g in part.groups if g.model.name == "j2").idx
    h0 = cscm.initial_history(next(g for g in part.groups if g.model.name == "cscm").params)
    assert np.array_equal(part.pts.hist[concrete, :len(h0)], np.tile(h0, (concrete.size, 1)))
    assert np.all(part.pts.hist[concrete, len(h0):] == 0.0)
    assert np.all(part.pts.hist[steel] == 0.0) and h0[0] > 0.0
    for _ in range(50):
        s.step()
    assert np.all(np.isfinite(part.pts.sig)) and np.all(np.isfinite(part.nodes.x))
