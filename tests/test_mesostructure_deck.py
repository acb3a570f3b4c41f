"""[body.mesostructure]: phases mapped to materials when the model is built."""

import numpy as np
import pytest

from sphdyn.deck import DeckError, loads_deck
from sphdyn.model import build_model

DECK = """
[run]
dimension = 2
t_end = 1e-4
seed = {seed}
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
[[material]]
name = "itz"
model = "elastic"
density = 2000.0
E = 1.5e10
nu = 0.2
[[body]]
name = "specimen"
material = "mortar"
dx = 1e-3
geometry = {{ shape = "box", lo = [0, 0], hi = [0.1, 0.1] }}
[body.mesostructure]
aggregate_fraction = 0.4
max_aggregate_size = "12 mm"
itz_thickness = "1 mm"
aggregate = "stone"
itz = "itz"
"""


def _model(seed=1, text=DECK):
    return build_model(loads_deck(text.format(seed=seed)))


def test_phases_become_materials_with_their_densities():
    # 10,000 particles; the generator hits the aggregate fraction on the
    # particles to one voxel (docs/mesostructure.md): within 2 points of 0.4.
    # Each particle takes its phase material's density, mass rho dx^2 and
    # wave speed; the ITZ exists because itz_thickness = dx.
    m = _model()
    p = m.particles
    frac = np.bincount(p.mat, minlength=3) / p.n
    assert frac[1] == pytest.approx(0.4, abs=0.02)
    assert frac[2] > 0.02 and frac[0] > 0.2
    for k, rho in enumerate((2200.0, 2700.0, 2000.0)):
        sel = p.mat == k
        assert np.all(p.rho0[sel] == rho) and np.allclose(p.m[sel], rho * 1e-6)
    assert p.c[p.mat == 1].min() > p.c[p.mat == 0].max()  # stiffer aggregate
    assert sorted(g.name for g in m.groups) == ["itz", "mortar", "stone"]


def test_seeded_by_run_seed():
    a, b, c = (_model(s).particles.mat for s in (1, 1, 2))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_bad_phase_material_is_rejected_before_building():
    with pytest.raises(DeckError, match="gravel"):
        loads_deck(DECK.format(seed=0).replace('aggregate = "stone"', 'aggregate = "gravel"'))


def test_phase_is_an_output_field_and_the_cli_draws_slices(tmp_path):
    # The phase per particle is written with the frames (ParaView field
    # "phase"), consistent with the materials; `sphdyn mesostructure` prints
    # the statistics and writes the slice image without running the deck.
    from sphdyn.cli import main
    from sphdyn.io import list_frames, read_frame
    from sphdyn.simulation import Simulation

    text = DECK.format(seed=3) + '[output]\nfields = ["phase", "material"]\nprogress = false\n'
    sim = Simulation.from_deck(loads_deck(text), tmp_path / "run")
    sim.run(max_steps=1)
    f = read_frame(list_frames(tmp_path / "run")[0])[2]
    assert np.array_equal(f["phase"], f["material"])  # materials listed in phase order
    deck = tmp_path / "d.toml"
    deck.write_text(text)
    assert main(["mesostructure", str(deck), "--out", str(tmp_path / "ph")]) == 0
    assert (tmp_path / "ph" / "phases_specimen.png").stat().st_size > 2000
