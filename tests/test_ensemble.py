"""Ensemble runner on Dask: seeds, resuming, failures, worker-count independence."""

import csv
import json

import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.deck import load_deck, loads_deck
from sphdyn.ensemble import (RESULT, SampleSpec, count_main_cracks, default_layout,
                             parse_vary, plan_samples, plot_mass_histograms, run_sample,
                             sample_seed)
from sphdyn.io import read_frame
from sphdyn.io.frames import list_frames
from sphdyn.simulation import Simulation

from decks import concrete_disc_2d

pytest.importorskip("distributed")

# The paper's disc in 2D at a coarse 5 mm spacing (316 particles, ~300 steps,
# about a second per sample), random uniform masses on [0, 2] m0.
TINY = concrete_disc_2d(
    "5 mm", "150 us", "50 us", ["mass", "damage", "velocity"], seed=11,
    body='mass = { distribution = "uniform", low = 0.0, high = 2.0 }')


@pytest.fixture
def deck(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def _table(out):
    with open(out / "ensemble.csv", newline="") as f:
        return list(csv.DictReader(f))


def _final(sample_dir):
    return read_frame(list_frames(sample_dir)[-1])[2]


def test_seeds_are_deterministic_distinct_and_shared_across_the_grid(deck, tmp_path):
    assert sample_seed(11, 0) == sample_seed(11, 0)
    seeds = [sample_seed(11, r) for r in range(100)]
    assert len(set(seeds)) == 100 and sample_seed(12, 0) != seeds[0]
    specs = plan_samples(deck, 3, ["sph.support_scale=0.7,1.5"], tmp_path / "o")
    assert [s.index for s in specs] == list(range(6))
    assert [s.seed for s in specs] == seeds[:3] * 2  # common random numbers
    assert specs[4].vary == {"sph.support_scale": "1.5"}
    assert specs[4].overrides == ("sph.support_scale=1.5", f"run.seed={seeds[1]}")
    assert specs[4].outdir.endswith("sample_0004")
    # a deck that is valid only with its --vary key still gets the deck's seed
    lacking = tmp_path / "lacking.toml"
    lacking.write_text(TINY.replace('distribution = "uniform", low = 0.0, high = 2.0',
                                    'distribution = "lognormal"'))
    specs = plan_samples(lacking, 2, ["body.disc.mass.sigma=0,0.5"], tmp_path / "o")
    assert [s.seed for s in specs] == seeds[:2] * 2


def test_vary_parsing_and_default_layout():
    assert parse_vary(["a.b=1,2", "c=x"]) == [("a.b", ["1", "2"]), ("c", ["x"])]
    for bad in (["a.b"], ["=1"], ["a="], ["a=1", "a=2"]):
        with pytest.raises(ValueError):
            parse_vary(bad)
    # workers x threads = cores: 2 single-thread workers on 2 cores, or one
    # 2-thread worker for a single sample
    assert default_layout(10, cores=2) == (2, 1)
    assert default_layout(1, cores=2) == (1, 2)
    assert default_layout(5, cores=2, workers=1) == (1, 2)


def test_main_crack_count_counts_separate_crossings_of_the_mid_section():
    # 2D lattice 40 x 40, dx = 1. Failed: a crushed zone at the bottom (rows
    # 0-3), two vertical bands (columns 10-11 and 28) from the bottom to row
    # 30 joining the crushed zone, an isolated failed particle at mid-height,
    # and a band that stops below the mid-section (column 20, rows 0-12).
    i, j = np.meshgrid(np.arange(40), np.arange(40), indexing="ij")
    x0 = np.stack([i.ravel() + 0.5, j.ravel() + 0.5, 0 * i.ravel()], axis=1)
    col, row = x0[:, 0] - 0.5, x0[:, 1] - 0.5
    d = np.zeros(len(x0))
    d[row <= 3] = 1.0
    d[((col == 10) | (col == 11) | (col == 28)) & (row <= 30)] = 1.0
    d[(col == 20) & (row <= 12)] = 1.0
    d[(col == 35) & (row == 20)] = 1.0
    m = np.ones(len(x0))
    assert count_main_cracks(x0, d, m, 1.0, dim=2) == 2
    # a crack of zero-mass particles is not a failure of the material
    m2 = m.copy()
    m2[col == 28] = 0.0
    assert count_main_cracks(x0, d, m2, 1.0, dim=2) == 1
    assert count_main_cracks(x0, np.zeros(len(x0)), m, 1.0, dim=2) == 0


# A body with phases of different densities (a mesostructure) and an initial
# crack, with a random mass field: 30 x 30 particles, elastic.
MESO = """
[run]
dimension = 2
t_end = 1e-5
seed = 5
[[material]]
name = "mortar"
model = "elastic"
density = 2200.0
E = 2.5e10
nu = 0.2
[[material]]
name = "stone"
model = "elastic"
density = 2700.0
E = 5.0e10
nu = 0.2
[[body]]
name = "specimen"
material = "mortar"
dx = 1e-3
geometry = { shape = "box", lo = [0, 0], hi = [0.03, 0.03] }
mass = { distribution = "uniform", low = 0.5, high = 1.5 }
[[body.crack]]
shape = "box"
lo = [0.01, 0.01, 0]
hi = [0.02, 0.012, 0]
[body.mesostructure]
aggregate_fraction = 0.3
max_aggregate_size = "6 mm"
aggregate = "stone"
[output]
progress = false
vtk = false
"""
CRACKED = TINY.replace("[[wall]]", """[[body.crack]]
shape = "box"
lo = ["-10 mm", "40 mm", 0]
hi = ["10 mm", "45 mm", 0]
[[wall]]""")


@pytest.mark.parametrize("text", [CRACKED, MESO], ids=["cracked", "mesostructure"])
def test_mass_histogram_plots_the_field_the_model_drew(text, tmp_path, monkeypatch):
    # The histogram shows the masses the model drew (m0 f s of the solid
    # particles, the axes of the requested law), read from the model: no
    # second draw. Without a mesostructure they are the particle masses;
    # with one, the masses are those times rho_phase / rho of the body's
    # material. Initial-crack particles (zero mass) are left out.
    from sphdyn.heterogeneity import mass, plots

    sim = Simulation.from_deck(loads_deck(text), tmp_path / "run")
    drawn = []
    real = plots.plot_mass_histogram

    def spy(masses, path, **kw):
        drawn.append((np.array(masses), kw))
        return real(masses, path, **kw)

    def no_second_draw(*args, **kwargs):
        raise AssertionError("the histogram drew the mass field again")

    monkeypatch.setattr(plots, "plot_mass_histogram", spy)
    monkeypatch.setattr(mass, "mass_field", no_second_draw)
    monkeypatch.setattr(mass, "body_rng", no_second_draw)
    paths = plot_mass_histograms(sim, tmp_path / "run")
    assert paths == [tmp_path / "run" / "plots" / "mass_histogram.png"]
    assert paths[0].stat().st_size > 5000
    assert drawn[0][1]["dimension"] == sim.deck.run.dimension
    (masses, kw), = drawn
    (draw,) = sim.model.mass_draws.values()
    p = sim.particles
    rows = draw.rows[draw.solid]
    assert 0 < rows.size < draw.rows.size and np.all(p.m[draw.rows[~draw.solid]] == 0)
    assert kw["m0"] == draw.m0 and kw["scale"] == draw.scale
    phase_over_body = p.rho0[rows] * p.vol0[rows] / draw.m0
    assert np.allclose(masses * phase_over_body, p.m[rows], rtol=1e-12, atol=0)
    if text is MESO:
        assert len(np.unique(p.rho0[rows])) == 2  # both phases carry a drawn mass


@pytest.fixture(scope="module")
def ensemble(tmp_path_factory):
    """One ensemble shared by the tests below (each Dask worker process pays
    the CSCM compilation, ~7 s, so clusters are started sparingly).

    2 replicates x 2 values of domain.margin: 1.0 (the default) runs to the
    end, 0.001 makes the guard stop the run (particles leave the box). (An
    invalid value is refused before anything starts:
    test_bad_input.py; an invalid sample is recorded: test below.) Run on
    2 worker processes.
    """
    base = tmp_path_factory.mktemp("ensemble")
    deck = base / "tiny.toml"
    deck.write_text(TINY)
    out = base / "ens"
    args = ["ensemble", str(deck), "--samples", "2", "--vary",
            "domain.margin=1.0,0.001", "--out", str(out), "-q", "--threads", "1",
            "--workers", "2"]
    assert main(args) == 0
    return deck, out, args


def test_an_invalid_sample_is_recorded_not_raised(deck, tmp_path):
    # e.g. the deck file edited between the plan and the run: the sample's
    # record says "invalid" with the deck's message
    spec = SampleSpec(0, 0, 1, {}, ("domain.margin=-1",), str(deck),
                      str(tmp_path / "sample_0000"))
    rec = run_sample(spec)
    assert rec["status"] == "invalid"
    assert "domain.margin" in rec["error"] and "Fix:" in rec["error"]
    assert json.loads((tmp_path / "sample_0000" / RESULT).read_text())["status"] == \
        "invalid"


@pytest.mark.slow
def test_ensemble_records_failures_resumes_and_reports(ensemble, capsys):
    # The failures are recorded and the others complete.
    deck, out, args = ensemble
    rows = _table(out)
    assert [r["status"] for r in rows] == ["completed"] * 2 + ["failed"] * 2
    assert "left the domain box" in rows[2]["error"]
    assert rows[0]["domain.margin"] == "1.0"
    for r in rows[:2]:
        assert float(r["peak_contact_force"]) > 0
        assert float(r["peak_contact_force_mean"]) > 0
        assert 0 < float(r["damaged_volume_fraction"]) < 1
        assert float(r["final_kinetic_energy"]) < float(r["initial_kinetic_energy"])
        assert float(r["dissipated_energy"]) > 0
    assert (out / "ensemble_damage.png").stat().st_size > 10000
    assert (out / "sample_0000" / "plots" / "mass_histogram.png").exists()
    resolved = load_deck(out / "sample_0001" / "deck.resolved.toml")
    assert resolved.run.seed == sample_seed(11, 1)

    # interrupted run: sample 1 lost its marker (as if killed before the
    # end). Re-running (on 1 worker) recomputes only it and retries the
    # failed ones; completed sample 0 is untouched (marker and frames keep
    # their modification times) and sample 1 comes out bitwise the same.
    marker0 = out / "sample_0000" / "result.json"
    before = marker0.stat().st_mtime_ns
    frames0 = [f.stat().st_mtime_ns for f in list_frames(out / "sample_0000")]
    final1 = _final(out / "sample_0001")
    (out / "sample_0001" / "result.json").unlink()
    capsys.readouterr()
    assert main(args[:-1] + ["1"]) == 0
    assert "1 already done, 3 to run" in capsys.readouterr().out
    assert marker0.stat().st_mtime_ns == before
    assert [f.stat().st_mtime_ns for f in list_frames(out / "sample_0000")] == frames0
    again = _final(out / "sample_0001")
    for key in final1:
        assert np.array_equal(final1[key], again[key]), key
    assert [r["status"] for r in _table(out)][:2] == ["completed"] * 2

    # the report alone is rewritten without running anything
    (out / "ensemble.csv").unlink()
    assert main(["ensemble", str(deck), "--report", "--out", str(out)]) == 0
    assert len(_table(out)) == 4


@pytest.mark.slow
def test_same_seed_same_result_with_1_or_2_workers_and_direct_run(ensemble, tmp_path):
    # Each sample is a pure function of its resolved deck: the final frames
    # are bitwise equal whether 1 worker ran them (here, without --vary) or
    # 2 workers (the shared ensemble, domain.margin = 1.0 = the default), and
    # equal to a direct in-process run of the deck with that seed. Two seeds
    # give different damage patterns (random masses change where it cracks).
    deck, out2, _ = ensemble
    out1 = tmp_path / "w1"
    assert main(["ensemble", str(deck), "--samples", "2", "--out", str(out1),
                 "--workers", "1", "--threads", "1", "-q"]) == 0
    for k in range(2):
        a = _final(out1 / f"sample_{k:04d}")
        b = _final(out2 / f"sample_{k:04d}")
        for key in a:
            assert np.array_equal(a[key], b[key]), (k, key)
    for x, y in zip(_table(out1), _table(out2)[:2]):
        for col in ("peak_contact_force", "peak_contact_force_mean", "dissipated_energy",
                    "damaged_volume_fraction", "main_cracks", "final_kinetic_energy"):
            assert x[col] == y[col], col
    direct = load_deck(deck, [f"run.seed={sample_seed(11, 1)}"])
    Simulation.from_deck(direct, tmp_path / "direct").run()
    d = _final(tmp_path / "direct")
    s1 = _final(out1 / "sample_0001")
    for key in d:
        assert np.array_equal(d[key], s1[key]), key
    s0 = _final(out1 / "sample_0000")
    assert not np.array_equal(s0["mass"], s1["mass"])
    failed0, failed1 = s0["damage"] >= 0.9, s1["damage"] >= 0.9
    assert failed0.any() and failed1.any()
    assert (failed0 != failed1).sum() > 0.2 * min(failed0.sum(), failed1.sum())
    rec = json.loads((out1 / "sample_0000" / "result.json").read_text())
    assert rec["status"] == "completed" and rec["seed"] == sample_seed(11, 0)
