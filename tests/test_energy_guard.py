"""Issue 57: energy made from nothing, and the guard on the energy balance.

What is pinned here, with its tolerance:

* the reported set-up (a quarter block of selective-reduced hexes, rollers on
  its symmetry planes, a rigid wall with the default contact thickness, 200
  m/s) keeps its energy: at most 3 % during the contact and 0.5 % at the end
  (it made 13 % by 75 us before the fix); one-point hexes alike;
* the guard stops a run that makes energy in a part (elements booking twice
  their work): status
  "energy_error", exit status 1, the diagnosis naming the part and its
  element, the output so far kept; it names the part an interaction pumps
  energy into, and that interaction; "warn" runs on and keeps the
  diagnosis; a conserving run never hears from it;
* the deck keys are validated (range, type, choice) with the field named.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from decks import ROLLERS
from sphdyn.cli import main
from sphdyn.deck import DeckError, loads_deck
from sphdyn.watchers.guards import EnergyError
from sphdyn.interactions.base import InteractionBase
from sphdyn.io import read_history_csv
from sphdyn.simulation import Simulation

#: a quarter block (20 mm, 4 x 4 x 4 hexes) of a soft J2 metal at 200 m/s onto
#: a rigid wall with the default contact thickness, rollers on x = 0 and
#: y = 0; the metal spreads on the wall, so the elements at its foot distort
QUARTER = """
[run]
dimension = 3
t_end = "{t_end}"
{run}
[[material]]
name = "metal"
model = "j2"
density = "7850 kg/m^3"
K = "160 GPa"
G = "80 GPa"
yield_stress = "50 MPa"
hardening_modulus = "1 MPa"
[[mesh]]
name = "block"
material = "metal"
integration = "{integration}"
block = {{lo = [0, 0, "2.6 mm"], hi = ["20 mm", "20 mm", "22.6 mm"], divisions = [4, 4, 4]}}
velocity = [0, 0, "-200 m/s"]
{rollers}
[[wall]]
name = "rigid"
point = [0, 0, 0]
normal = [0, 0, 1]
[domain]
margin = 5
[output]
every = "25 us"
history_every = 1
progress = false
vtk = false
"""


def quarter(t_end="75 us", integration="selective_reduced", run=""):
    return loads_deck(QUARTER.format(t_end=t_end, integration=integration, run=run, rollers=ROLLERS))


def energies(outdir):
    h = read_history_csv(outdir / "history.csv")
    return h["E_total"], h


@pytest.mark.parametrize("integration", ["selective_reduced", "one_point"])
def test_the_reported_set_up_keeps_its_energy(tmp_path, integration):
    """75 us of the issue's set-up: the total energy within 3 % of the first
    row's at every row and 0.5 % at the end. The 3 %: while the wall's mass
    spring (omega dt = sqrt(0.1)) holds the nodes, the kick's mid-step work
    books its energy with an error of order (omega dt)^2 / 8 of the
    spring's, about 2 % here, gone when the contact ends; 0.5 % then bounds
    what is left (0.1 % measured). Before the fix the selective-reduced run
    made 13 % by 75 us (its elements' distorted points booked over equal
    shares, and the quarter's centre driven into the wall by a thinner
    contact)."""
    s = Simulation.from_deck(quarter(integration=integration), tmp_path).run(threads=1)
    assert s["status"] == "completed" and "energy_warning" not in s
    e, h = energies(tmp_path)
    assert h["contacts_rigid_block"].max() > 0
    assert np.abs(e - e[0]).max() < 0.03 * e[0]
    assert abs(e[-1] - e[0]) < 0.005 * e[0]


def double_the_work(monkeypatch):
    """A crafted energy source: the selective-reduced points book twice the
    work their stresses do (energy made in the part 'block')."""
    import importlib

    sp = importlib.import_module("sphdyn.parts.fem.solid_part")
    weigh = sp.weigh_point_work

    def twice(e, e_old, rho, wm, m):
        weigh(e, e_old, rho, wm, m)
        e[:] = e_old + 2.0 * (e - e_old)

    monkeypatch.setattr(sp, "weigh_point_work", twice)


def test_the_guard_stops_a_run_that_makes_energy_in_a_part(tmp_path, monkeypatch, capsys):
    """Elements booking twice their work: the guard (default limit 5 %)
    stops the run with status "energy_error", exit status 1, naming the mesh
    and its element of the largest specific energy; the history holds the
    row past the limit and summary.json the diagnosis."""
    double_the_work(monkeypatch)
    path = tmp_path / "quarter.toml"
    path.write_text(QUARTER.format(t_end="75 us", integration="selective_reduced", run="",
                                   rollers=ROLLERS))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "-q",
                 "--threads", "1"]) == 1
    err = capsys.readouterr().err
    assert "energy balance is off" in err and "All output written so far is kept" in err
    summary = json.loads((tmp_path / "out/summary.json").read_text())
    assert summary["status"] == "energy_error"
    d = summary["diagnosis"]
    assert "Part 'block' gained the most" in d
    assert "largest specific internal energy" in d and "element " in d
    assert "'rigid_block'" in d and "'x0'" in d  # the interactions acting on it
    e, h = energies(tmp_path / "out")
    assert abs(e[-1] - e[0]) > 0.05 * np.abs(e).max()  # the row past the limit kept
    assert h["time"][-1] < 75e-6
    assert list((tmp_path / "out/frames").glob("*.h5"))


def test_warn_runs_on_and_keeps_the_diagnosis(tmp_path, monkeypatch):
    """action = "warn": the same run goes on to its end, status
    "completed", the diagnosis (printed once) in summary.json."""
    double_the_work(monkeypatch)
    deck = quarter(run='energy_error_action = "warn"')
    s = Simulation.from_deck(deck, tmp_path).run(threads=1)
    assert s["status"] == "completed"
    assert s["energy_error_max_rel"] > 0.05
    assert s["energy_warning"].startswith("warning: at t =")
    assert "Part 'block'" in s["energy_warning"]


class Pump(InteractionBase):
    """A test double: raises the speed of its part's items by 1 % a step
    after the kick, outside every book (energy from nothing)."""

    def __init__(self, part):
        self.name, self.part = "pump", part

    def forces(self, t, dt, a_out):
        return None

    def constrain(self, t, dt):
        self.part.kin.v *= 1.01

    def columns(self, t):
        return {}


TWO_BLOCKS = QUARTER.replace("{rollers}", """[[mesh]]
name = "free"
material = "metal"
block = {{lo = ["40 mm", 0, "10 mm"], hi = ["50 mm", "10 mm", "20 mm"], divisions = [1, 1, 1]}}
velocity = [0, 0, "-20 m/s"]
{rollers}""", 1)


def test_the_guard_names_the_part_an_interaction_pumps_and_the_interaction(tmp_path):
    """Two meshes; a pump on the second ('free', a cube at 20 m/s) makes
    energy: the default limit (5 %) stops the run, the diagnosis names
    'free', not the struck block (whose contact's transient, 2 %, stays
    below the limit), and the pump among the interactions acting on it."""
    deck = loads_deck(TWO_BLOCKS.format(t_end="75 us", integration="selective_reduced",
                                        run="", rollers=ROLLERS))
    sim = Simulation.from_deck(deck, tmp_path)
    s = sim.stepper
    s.interactions.append(Pump(s.part("free")))
    with pytest.raises(EnergyError) as exc:
        sim.run(threads=1)
    d = exc.value.diagnosis
    assert "Part 'free' gained the most" in d and "'pump'" in d
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "energy_error"


@pytest.mark.parametrize("line,words", [
    ("energy_error_limit = 0", "energy_error_limit"),
    ("energy_error_limit = 1.5", "energy_error_limit"),
    ('energy_error_limit = "a lot"', "energy_error_limit"),
    ('energy_error_action = "explode"', "energy_error_action"),
])
def test_the_guard_keys_are_validated(line, words):
    with pytest.raises(DeckError) as exc:
        quarter(run=line)
    msg = str(exc.value)
    assert words in msg and "Fix" in msg


def test_a_transient_past_the_limit_is_waited_out_a_lasting_gain_is_not(monkeypatch):
    """The guard acts only when the error has stayed past the limit for
    EnergyGuard.PERSIST steps: a 7 % spike over 20 steps (a penalty contact's
    booking transient, tests/test_erosion.py) passes, the same 7 % held
    stops the run at exactly PERSIST steps after it began, and a dip below
    the limit starts the count again."""
    from types import SimpleNamespace

    from sphdyn.watchers import monitors
    from sphdyn.io.history import History

    monkeypatch.setattr(monitors, "energy_diagnosis", lambda s, *a: "made energy")
    recorder = SimpleNamespace(_row=None)

    def run(errors):
        guard = monitors.EnergyGuard(recorder, History(), limit=0.05)
        s = SimpleNamespace(step_count=0)
        for k, err in enumerate(errors):
            s.step_count = k
            recorder._row = {"E_total": 100.0 + 100.0 * err, "E_kinetic": 100.0}
            guard.after_kick(s)
            guard.after_step(s)
        return guard

    p = monitors.EnergyGuard.PERSIST
    run([0.0] * 10 + [0.07] * 20 + [0.0] * 500)  # the transient: no stop
    run([0.0] * 10 + ([0.07] * (p - 1) + [0.0]) * 3)  # dips reset the count
    assert run([0.0] * 10 + [0.07] * p)._since == 10  # held p steps: not yet
    with pytest.raises(EnergyError, match="made energy"):
        run([0.0] * 10 + [0.07] * (p + 1))  # step 10 + p stops it
