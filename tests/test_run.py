"""Whole runs through the Python API and the CLI: output, restart, guards."""

import json
import shutil
from pathlib import Path

import meshio
import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.deck import loads_deck
from sphdyn.watchers.guards import SimulationFailed
from sphdyn.analysis.fragments import window_mean_force
from sphdyn.io import read_checkpoint, read_frame, read_history_csv, read_pvd
from sphdyn.simulation import Simulation
from decks import SMALL_DISC



def _sim(tmp_path, name, t_end="3 ms", ck=0, **extra):
    text = SMALL_DISC.format(t_end=t_end, ck=ck)
    for key, val in extra.items():
        text = text.replace(key, val)
    return Simulation.from_deck(loads_deck(text), tmp_path / name)


def test_run_writes_everything_paraview_can_read(tmp_path):
    sim = _sim(tmp_path, "run")
    summary = sim.run()
    out = tmp_path / "run"
    assert summary["status"] == "completed"
    for name in ("deck.resolved.toml", "history.csv", "summary.json", "checkpoint.h5",
                 "particles.pvd", "plots/energies.png", "plots/forces.png"):
        assert (out / name).exists(), name
    entries = read_pvd(out / "particles.pvd")
    assert len(entries) >= 7  # t = 0, 0.5, ..., 3 ms
    times = [t for t, _ in entries]
    assert times[0] == 0.0 and abs(times[-1] - 3e-3) < 1e-9
    mesh = meshio.read(out / entries[-1][1])
    t, step, fields, _ = read_frame(sorted((out / "frames").glob("*.h5"))[-1])
    assert np.allclose(mesh.points, fields["position"])
    assert mesh.point_data["stress"].shape == (sim.particles.n, 9)
    assert np.allclose(mesh.point_data["plastic_strain"], sim.particles.hist[:, 0])
    hist = read_history_csv(out / "history.csv")
    assert hist["F_wall_floor"].max() > 0
    assert sim.particles.hist[:, 0].max() > 0  # it yielded at the contact


TL_TWO_BODIES = {
    "[[body]]": '[sph]\nformulation = "total_lagrangian"\n[[body]]',
    "[[wall]]": """[[body]]
name = "second"
material = "rubber"
dx = 1e-3
velocity = [0, -10.0, 0]
geometry = { shape = "cylinder", centre = [0.001, 0.019, 0], radius = 0.006 }
[[wall]]""",
}


TL_UPDATED = {**TL_TWO_BODIES, "[[body]]": TL_TWO_BODIES["[[body]]"].replace(
    'formulation = "total_lagrangian"',
    'formulation = "total_lagrangian"\nreference_update_every = 15')}


@pytest.mark.parametrize("variant", ["updated_lagrangian", "total_lagrangian",
                                     "total_lagrangian_updated_reference"])
def test_restart_continues_to_the_same_result(tmp_path, variant):
    # An interrupted run restarted from its checkpoint must reproduce the
    # uninterrupted run bitwise (same neighbour list, same operation order);
    # the total-Lagrangian variant has two bodies in particle contact, so the
    # contact neighbour list is part of the checkpoint too.
    extra = {"updated_lagrangian": {}, "total_lagrangian": TL_TWO_BODIES,
             "total_lagrangian_updated_reference": TL_UPDATED}[variant]
    full = _sim(tmp_path, "full", **extra)
    full.run()
    if extra:
        h = read_history_csv(tmp_path / "full/history.csv")
        assert h["contacts_bodies"].max() > 0  # the bodies did touch
    part = _sim(tmp_path, "part", ck=20, **extra)
    part.run(max_steps=50)  # "interrupted" after 50 steps (checkpoint at 40 and exit)
    ck_t = read_checkpoint(tmp_path / "part" / "checkpoint.h5")[1]["t"]
    assert 0 < ck_t < 3e-3
    assert main(["restart", str(tmp_path / "part"), "-q"]) == 0
    _, _, f_full, _ = read_frame(sorted((tmp_path / "full/frames").glob("*.h5"))[-1])
    _, _, f_part, _ = read_frame(sorted((tmp_path / "part/frames").glob("*.h5"))[-1])
    for key in f_full:
        assert np.array_equal(f_full[key], f_part[key]), key
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert np.array_equal(h_full["time"], h_part["time"])
    assert np.array_equal(h_full["E_total"], h_part["E_total"])
    # the wall impulse is carried over too (it is not recomputable from the state)
    assert np.array_equal(h_full["I_wall_floor"], h_part["I_wall_floor"])
    assert np.interp(ck_t, h_full["time"], h_full["I_wall_floor"]) > 0


#: SMALL_DISC pressed onto its floor through a prescribed velocity of its
#: top cap (1 m/s down, the disc starting at the same speed): the cap's
#: reactions do work, so W_external is nonzero
PRESSED_DISC = {
    "velocity = [0, -5.0, 0]": "velocity = [0, -1.0, 0]",
    "[[wall]]": """[[set]]
name = "cap"
region = { shape = "box", lo = [-1, 0.0112, -1], hi = [1, 1, 1] }
[[boundary]]
set = "cap"
type = "velocity"
velocity = [0, -1.0, 0]
[[wall]]""",
}


def test_restart_restores_the_external_work(tmp_path):
    # A restart must continue the energy accumulators, not only the
    # particles: with a prescribed-velocity boundary W_external grows during
    # the run, and a restart that started it again from 0 would shift
    # W_external and E_total by the work done before the checkpoint. Run
    # through, and stopped after 150 steps (exit checkpoint) then restarted:
    # every history column and particle array bitwise equal.
    full = _sim(tmp_path, "full", t_end="2 ms", **PRESSED_DISC)
    full.run()
    part = _sim(tmp_path, "part", t_end="2 ms", ck=1000, **PRESSED_DISC)
    part.run(max_steps=150)
    _, scalars, _ = read_checkpoint(tmp_path / "part" / "checkpoint.h5")
    assert 0 < scalars["t"] < 2e-3
    rest = Simulation.from_directory(tmp_path / "part")
    assert rest.stepper.work_external == scalars["work_external"] != 0.0
    rest.run()
    for name, arr in full.particles.arrays().items():
        assert np.array_equal(arr, getattr(rest.particles, name)), name
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert list(h_full) == list(h_part)
    for col in h_full:
        assert np.array_equal(h_full[col], h_part[col]), col
    # the work before the checkpoint is a sizeable part of the total (so a
    # restart from W = 0 is no last-digit difference) and the cap did press
    before = np.interp(scalars["t"], h_full["time"], h_full["W_external"])
    assert abs(before) > 0.01 * abs(h_full["W_external"][-1]) > 0.0
    assert h_full["F_wall_floor"].max() > 0.0


def test_particles_leaving_the_domain_stop_the_run_with_a_diagnosis(tmp_path):
    sim = _sim(tmp_path, "escape", t_end="20 ms",
               **{"[output]": "[domain]\nlo = [-0.02, -0.02, 0]\nhi = [0.02, 0.02, 0]\n"
                  "[output]"})
    with pytest.raises(SimulationFailed) as err:
        sim.run()
    msg = err.value.diagnosis
    assert "left the domain box" in msg and "#" in msg
    out = tmp_path / "escape"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert (out / "history.csv").exists() and len(list((out / "frames").glob("*.h5"))) >= 2


def test_nan_is_caught_with_the_quantity_named(tmp_path):
    sim = _sim(tmp_path, "nan")
    sim.particles.sig[3, 0, 0] = np.nan
    with pytest.raises(SimulationFailed) as err:
        sim.run()
    assert "non-finite" in err.value.diagnosis and "#3" in err.value.diagnosis


def test_time_step_collapse_is_caught(tmp_path):
    sim = _sim(tmp_path, "collapse")
    sim.particles.c[7] = 1e12  # a wave speed that makes dt collapse
    with pytest.raises(SimulationFailed) as err:
        sim.run()
    assert "time step collapsed" in err.value.diagnosis
    assert "particle 7" in err.value.diagnosis


def test_cli_check_run_export_plot_info(tmp_path, capsys):
    deck = tmp_path / "small.toml"
    deck.write_text(SMALL_DISC.format(t_end="1 ms", ck=0))
    assert main(["check", str(deck)]) == 0
    assert "OK" in capsys.readouterr().out
    out = tmp_path / "cli"
    assert main(["run", str(deck), "--out", str(out), "-q", "--threads", "1"]) == 0
    assert (out / "summary.json").exists()
    shutil.rmtree(out / "vtk")
    assert main(["export", str(out)]) == 0
    assert len(list((out / "vtk").glob("*.vtu"))) >= 3
    assert main(["export", str(out), "--format", "csv"]) == 0
    assert main(["plot", str(out)]) == 0
    assert main(["info"]) == 0
    assert "numba" in capsys.readouterr().out


def test_cli_rejects_a_bad_deck_before_running(tmp_path, capsys):
    deck = tmp_path / "bad.toml"
    deck.write_text(SMALL_DISC.format(t_end="1 ms", ck=0).replace("dx = 1e-3", "dx = '3 MPa'")
                    .replace("nu = 0.3", "nu = 0.7\ncolour = 'red'"))
    assert main(["run", str(deck), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "dx" in err and "nu" in err and "colour" in err and "Fix:" in err
    assert not (tmp_path / "x").exists()  # nothing ran, nothing written
    assert main(["check", str(tmp_path / "missing.toml")]) == 2


def test_cli_bench_prints_one_json_line(capsys):
    assert main(["bench", "block3d", "--particles", "1000", "--steps", "5"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    rec = json.loads(line)
    for key in ("case", "particles", "steps", "threads", "seconds", "compile_seconds",
                "particle_steps_per_s"):
        assert key in rec
    assert rec["steps"] == 5 and rec["particles"] == 1000


def test_cli_bench_hex3d(capsys):
    """The hex8 benchmark: 10^3 elements (11^3 nodes), its own keys; --elements
    is refused for a particle case."""
    assert main(["bench", "hex3d", "--elements", "1000", "--steps", "5"]) == 0
    rec = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert rec["elements"] == 1000 and rec["nodes"] == 1331 and rec["steps"] == 5
    assert rec["element_steps_per_s"] > 0 and rec["bytes_per_element"] > 0
    assert main(["bench", "block3d", "--elements", "1000"]) == 2
    assert "--elements" in capsys.readouterr().err


def test_cli_bench_hvi_projects_the_event_time(capsys):
    """The drop-weight benchmark (coarse deck, 3 steps: the first steps need no
    contact yet): the projected event time is t_end / dt steps at the measured
    rate; --coarse is refused for the other cases."""
    assert main(["bench", "hvi", "--coarse", "--steps", "3"]) == 0
    rec = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert rec["case"] == "hvi" and rec["deck"].endswith("dropweight_coarse.toml")
    assert rec["particles"] == 36177 and rec["t_end"] == 0.02  # 35,397 + 780 stirrup nodes
    assert rec["event_steps"] == pytest.approx(rec["t_end"] / rec["dt"], rel=1e-12)
    assert rec["projected_event_seconds"] == pytest.approx(
        rec["event_steps"] * rec["seconds"] / rec["steps"], rel=1e-12)
    assert main(["bench", "block3d", "--coarse"]) == 2
    assert "--coarse" in capsys.readouterr().err


EXAMPLES = sorted(Path(__file__).parent.parent.glob("examples/*.toml"))


@pytest.mark.parametrize("deck", EXAMPLES, ids=[d.stem for d in EXAMPLES])
def test_every_example_deck_runs_two_steps(deck, tmp_path):
    assert main(["run", str(deck), "--out", str(tmp_path / deck.stem), "--max-steps",
                 "2", "-q"]) == 0


def test_probes_record_set_histories(tmp_path):
    # A probe on the whole disc records the mean velocity, which before the
    # impact equals the initial -5 m/s exactly, and the max plastic strain,
    # which grows once the contact zone yields.
    text = SMALL_DISC.format(t_end="3 ms", ck=0) + """
[[set]]
name = "all"
[[probe]]
set = "all"
quantities = ["velocity_y", "plastic_strain", "stress_yy"]
reduce = "max"
"""
    sim = Simulation.from_deck(loads_deck(text), tmp_path / "probe")
    sim.run()
    h = read_history_csv(tmp_path / "probe/history.csv")
    assert h["probe_all_velocity_y"][0] == -5.0
    assert h["probe_all_plastic_strain"][0] == 0.0
    assert h["probe_all_plastic_strain"][-1] > 0.0
    assert h["probe_all_plastic_strain"][-1] == sim.particles.hist[:, 0].max()


def test_probe_of_a_missing_history_variable_is_rejected_before_running(tmp_path):
    text = SMALL_DISC.format(t_end="1 ms", ck=0).replace('model = "j2"', 'model = "elastic"')
    text = text.replace("yield_stress = 2e5\nhardening_modulus = 1e6\n", "")
    text += '[[set]]\nname = "all"\n[[probe]]\nset = "all"\nquantities = ["plastic_strain"]\n'
    deck = tmp_path / "d.toml"
    deck.write_text(text)
    assert main(["check", str(deck)]) == 2


def test_run_deck_reuses_a_finished_run(tmp_path):
    # reuse: a folder with a summary is not run again (the deck need not even
    # be valid), its summary is returned; without reuse the deck is loaded
    import json

    from sphdyn.deck import DeckError
    from sphdyn.simulation import run_deck
    (tmp_path / "summary.json").write_text(json.dumps({"status": "completed", "steps": 7}))
    bad = tmp_path / "bad.toml"
    bad.write_text("[run]\n")
    assert run_deck(bad, tmp_path, reuse=True) == {"status": "completed", "steps": 7}
    with pytest.raises(DeckError):
        run_deck(bad, tmp_path)


def test_run_examples_picks_the_runs_of_an_example_script(tmp_path, monkeypatch):
    # the long run ("full") only with include_full, or read if found; --reuse
    # reads what is found and runs nothing
    import sphdyn.simulation as sim
    calls = []
    monkeypatch.setattr(sim, "run_deck", lambda deck, out, over, reuse, progress:
                        calls.append((out.name, reuse)))
    runs = {"coarse": ("c.toml", [], "c"), "full": ("f.toml", [], "f")}
    assert list(sim.run_examples(tmp_path, runs, "full")) == ["coarse"]
    assert calls == [("coarse", False)]
    (tmp_path / "out" / "full").mkdir(parents=True)
    (tmp_path / "out" / "full" / "summary.json").write_text("{}")
    calls.clear()
    assert list(sim.run_examples(tmp_path, runs, "full")) == ["coarse", "full"]
    assert calls == [("coarse", False), ("full", True)]  # found: read, not run again
    calls.clear()
    assert list(sim.run_examples(tmp_path, runs, "full", reuse=True)) == ["full"]
    assert calls == [("full", True)]
    calls.clear()
    sim.run_examples(tmp_path, runs, "full", include_full=True)
    assert calls == [("coarse", False), ("full", False)]


# ------------------------------------------------- the first two minutes (issue 57)
def test_remaining_time_leaves_out_compilation_and_waits_for_steady_steps():
    """The ETA (RemainingTime) of a first run: a first step of 17 s (Numba
    compiling) and then steps of 10 ms advancing 1 ns each. No estimate until
    5 steady steps are timed; then 1e-4 s left takes 1e5 steps of 10 ms =
    1000 s, not the 3:57:10 extrapolated from the first step. A later step
    during which Numba compiled (5 s) is left out too. Sums of equal floats:
    relative error of a few ulp (tolerance 1e-12)."""
    from sphdyn.watchers.monitors import RemainingTime

    eta = RemainingTime()
    assert eta.seconds(1e-4) is None
    eta.add(17.0, 1e-9)
    for _ in range(4):
        eta.add(0.01, 1e-9)
        assert eta.seconds(1e-4) is None  # fewer than 5 steady steps
    eta.add(0.01, 1e-9)
    assert eta.seconds(1e-4) == pytest.approx(1000.0, rel=1e-12)
    eta.add(5.0, 1e-9, compiled=True)
    assert eta.seconds(1e-4) == pytest.approx(1000.0, rel=1e-12)
    # the rate follows the run: 40 s of steps at 20 ms push the 10 ms ones out
    for _ in range(2000):
        eta.add(0.02, 1e-9)
    assert eta.seconds(1e-4) == pytest.approx(2000.0, rel=1e-9)


def test_the_progress_bar_says_compiling_and_shows_no_eta_before_steady_steps():
    """While Numba compiles (a kernel not in its cache), the bar shows
    'compiling kernels (first run only)' at once; after the step it shows no
    ETA until 5 steady steps are timed, then the ETA of the steady rate (a
    clock advancing 0.5 s per step of 1 us: at 6 us of 20 us, 14 steps left
    = 7 s, '00:07'); and compile_notice writes its line once, and nothing
    when told to be quiet."""
    import types

    import numba

    from sphdyn.watchers.monitors import COMPILING, Progress, compile_notice

    clock = iter(np.arange(0.0, 100.0, 0.5))
    bar = Progress(0.0, 2e-5, clock=lambda: float(next(clock)))
    s = types.SimpleNamespace(t=0.0)

    @numba.njit(cache=False)
    def fresh(x):  # never compiled before: a "numba:compile" event
        return x + 1

    shown = []
    try:
        fresh(1)
        assert bar.bar.postfix == COMPILING
        for k in range(1, 7):
            s.t = k * 1e-6
            bar.after_step(s)
            shown.append(bar.bar.postfix)
    finally:
        bar.close()
    assert shown == [""] * 5 + ["ETA 00:07"]
    said = []
    with compile_notice(said.append):
        numba.njit(cache=False)(lambda x: x * 2)(1)
        numba.njit(cache=False)(lambda x: x * 3)(1)
    assert len(said) == 1 and COMPILING in said[0]
    with compile_notice(None):
        numba.njit(cache=False)(lambda x: x * 4)(1)  # says nothing, raises nothing


def test_summary_text_says_how_the_run_ended_and_what_to_open(tmp_path):
    """The end of a run for a person (summary_text), from a summary as
    _summary makes it: status, time in us, steps, wall time, energy error in
    per cent, the wall's peak force in kN (81,600 N; 3D), a reaction in MN,
    and the files to open that exist; a stopped run says how to continue."""
    from sphdyn.simulation import summary_text

    (tmp_path / "plots").mkdir()
    (tmp_path / "plots" / "forces.png").write_bytes(b"")
    (tmp_path / "particles.pvd").write_text("")
    summary = {"status": "stopped", "signal": None, "time": 1.25e-5, "steps": 120,
               "steps_this_run": 120, "wall_seconds": 75.0, "dimension": 3,
               "energy_error_max_rel": 0.0123, "peak_F_wall_base": 81600.0,
               "peak_F_wall_base_mean": 69200.0, "force_window": 5e-6,
               "peak_clamped_reaction": 1.04e7}
    text = summary_text(summary, tmp_path)
    assert text.splitlines()[0] == ("sphdyn: stopped by --max-steps at t = 12.5 µs, "
                                    "step 120, in 1 min 15 s")
    for words in ("energy error: 1.23 %", "peak force on wall base: 81.6 kN "
                  "(5 µs mean 69.2 kN)", "peak reaction of clamped: 10.4 MN",
                  "particles.pvd    open in ParaView (0 frames)", "plots/           forces.png",
                  "summary.json", f"continue with: sphdyn restart {tmp_path}"):
        assert words in text, words
    summary.update(status="completed", dimension=2, peak_F_wall_base=812.0)
    del summary["peak_F_wall_base_mean"]
    text = summary_text(summary, tmp_path)
    assert "peak force on wall base: 812 N/m\n" in text and "continue" not in text


def test_the_cli_ends_a_run_with_a_summary_not_json_and_q_is_quiet(tmp_path, capsys):
    """`sphdyn run` used to end with a raw JSON line; it prints the summary
    for a person (no line of JSON), and summary.json keeps every value.
    With -q it prints nothing on stdout (warnings and errors only)."""
    deck = tmp_path / "small.toml"
    deck.write_text(SMALL_DISC.format(t_end="1 ms", ck=0))
    assert main(["run", str(deck), "--out", str(tmp_path / "a"), "--threads", "1",
                 "--max-steps", "30"]) == 0
    out = capsys.readouterr().out
    assert not any(line.lstrip().startswith("{") for line in out.splitlines()), out
    assert "stopped by --max-steps" in out and "particles.pvd" in out
    assert "summary.json" in out and "energy error" in out
    saved = json.loads((tmp_path / "a/summary.json").read_text())
    assert saved["status"] == "stopped" and saved["steps"] == 30
    assert "particle_steps_per_s" in saved
    assert main(["run", str(deck), "--out", str(tmp_path / "b"), "--threads", "1",
                 "--max-steps", "30", "-q"]) == 0
    assert capsys.readouterr().out == ""


def test_a_run_stopped_by_max_steps_ends_with_its_last_state_in_the_frames(tmp_path):
    """A run stopped by --max-steps wrote no frame of its last state (ParaView
    showed only t = 0). Now its last state is a frame, listed in the .pvd,
    marked as a stop frame; the restart drops it, so the frames of the
    stopped-and-restarted run are those of a run straight through (same
    names, times and fields). A run ending at t_end writes no second frame at
    t_end; one interrupted writes its last state too."""
    from sphdyn.io import read_frame_header

    part = _sim(tmp_path, "part", t_end="1 ms")
    summary = part.run(max_steps=25)
    assert summary["status"] == "stopped"
    entries = read_pvd(tmp_path / "part/particles.pvd")
    assert [t for t, _ in entries] == [0.0, summary["time"]]
    t, step, fields, attrs = read_frame(tmp_path / "part/frames/frame_00001.h5")
    assert (t, step) == (summary["time"], 25) and attrs.get("stop_frame")
    assert np.array_equal(fields["position"], part.particles.x)

    assert main(["restart", str(tmp_path / "part"), "-q"]) == 0
    full = _sim(tmp_path, "full", t_end="1 ms")
    full.run()
    names = [f.name for f in sorted((tmp_path / "full/frames").glob("*.h5"))]
    assert names == [f.name for f in sorted((tmp_path / "part/frames").glob("*.h5"))]
    for name in names:
        t_full, _, f_full, _ = read_frame(tmp_path / "full/frames" / name)
        t_part, _, f_part, a_part = read_frame(tmp_path / "part/frames" / name)
        assert t_full == t_part and not a_part.get("stop_frame")
        assert np.array_equal(f_full["position"], f_part["position"]), name
    times = [read_frame_header(tmp_path / "full/frames" / n)[0] for n in names]
    assert times.count(times[-1]) == 1 and times[-1] == pytest.approx(1e-3, rel=1e-12)
    assert read_pvd(tmp_path / "part/particles.pvd") == read_pvd(
        tmp_path / "full/particles.pvd")



def test_cscm_damage_modes_are_frame_fields_and_probe_quantities(tmp_path):
    """The CSCM's brittle and ductile damage (LS-DYNA NPLOT 2 and 3) as
    output fields and probe quantities: the last frame holds the particles'
    history columns exactly, the probe their largest value (the disc 0.2 ms
    after its impact, when both have grown)."""
    path = Path(__file__).parents[1] / "examples/disc_impact.toml"
    text = path.read_text() + """
[[set]]
name = "whole"
[[probe]]
set = "whole"
quantities = ["damage_brittle", "damage_ductile"]
reduce = "max"
"""
    deck = loads_deck(text, base_dir=path.parent, overrides=[
        'output.fields=["damage", "damage_brittle", "damage_ductile"]', "output.vtk=false",
        "output.progress=false", "run.t_end=2e-4", "output.every=2e-4"])
    sim = Simulation.from_deck(deck, tmp_path / "disc")
    sim.run()
    p = sim.particles
    _, _, fields, _ = read_frame(sorted((tmp_path / "disc/frames").glob("*.h5"))[-1])
    h = read_history_csv(tmp_path / "disc/history.csv")
    for name in ("damage_brittle", "damage_ductile"):
        column = p.hist[:, p.hist_names.index(name)]
        assert column.max() > 0.0, name
        assert np.array_equal(fields[name], column), name
        assert h[f"probe_whole_{name}"][-1] == column.max(), name
    # the applied damage is the larger of the two (nothing is recovered here
    # where the pressure is tensile) or the ductile one (where compressive)
    assert np.all(p.damage <= np.maximum(fields["damage_brittle"],
                                         fields["damage_ductile"]) + 1e-15)


#: a core of the small disc held fixed: its reaction carries the disc's impact
CORE = """
[[set]]
name = "core"
body = "disc"
region = { shape = "box", lo = [-0.002, 0.004, -1], hi = [0.002, 0.008, 1] }
[[boundary]]
set = "core"
type = "fixed"
"""


def test_the_summarys_peaks_are_those_of_the_history(tmp_path):
    # Each wall and boundary summarises its own history columns: the largest
    # normal force, the largest mean over the force window (from the impulse,
    # analysis.fragments.window_mean_force) and the largest magnitude of the
    # reaction. The history file holds the same numbers (%.17g), so the three
    # agree to round-off of the mean's interpolation (1e-12 relative).
    text = SMALL_DISC.format(t_end="1 ms", ck=0) + CORE
    summary = Simulation.from_deck(loads_deck(text), tmp_path / "out").run(progress=False)
    h = read_history_csv(tmp_path / "out" / "history.csv")
    assert summary["peak_F_wall_floor"] == pytest.approx(np.max(h["F_wall_floor"]),
                                                         rel=1e-12)
    mean = window_mean_force(h["time"], h["I_wall_floor"], summary["force_window"])
    assert summary["peak_F_wall_floor_mean"] == pytest.approx(np.max(mean), rel=1e-12)
    assert summary["peak_F_wall_floor_mean"] < summary["peak_F_wall_floor"]
    r = np.linalg.norm([h[f"core_reaction_{c}"] for c in "xyz"], axis=0)
    assert summary["peak_core_reaction"] == pytest.approx(np.max(r), rel=1e-12)
    assert summary["peak_core_reaction"] > 0.0
