"""[body.mesostructure]: phases mapped to materials when the model is built."""

import numpy as np
import pytest

from sphdyn.deck import DeckError, loads_deck
from sphdyn.build.model import build_model

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


# ------------------------------------------------------------- photo route
def _section_png(path, fraction=0.35):
    """A synthetic section (tests/data/make_section_image.py) saved as PNG."""
    import importlib.util
    from pathlib import Path

    from PIL import Image
    spec = importlib.util.spec_from_file_location(
        "make_section_image", Path(__file__).parent / "data" / "make_section_image.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    grey, truth = mod.synthetic_section(shape=(300, 300), fraction=fraction, seed=3)
    Image.fromarray((255 * grey).astype(np.uint8)).save(path)
    return truth.mean()


PHOTO = DECK.replace('aggregate_fraction = 0.4\nmax_aggregate_size = "12 mm"\n',
                     'photo = "section.png"\npixel_size = "0.4 mm"\n')


def test_photo_in_the_deck_sets_fraction_and_size(tmp_path, capsys):
    # 2D: the particles' aggregate fraction follows the photo's area
    # fraction (photo 120 mm wide, pieces of 3-14 mm, body 100 mm on a 1 mm
    # lattice): within 2 points, the tolerance for the photo route;
    # `sphdyn mesostructure` prints the photo's statistics next to the
    # generated ones.
    from sphdyn.cli import main
    from sphdyn.deck import load_deck

    truth = _section_png(tmp_path / "section.png")
    deck = tmp_path / "d.toml"
    deck.write_text(PHOTO.format(seed=1))
    m = build_model(load_deck(deck))
    frac = np.bincount(m.particles.mat, minlength=3)[1] / m.particles.n
    assert frac == pytest.approx(truth, abs=0.02)
    assert main(["mesostructure", str(deck), "--out", str(tmp_path / "ph")]) == 0
    out = capsys.readouterr().out
    assert "photo: area fraction" in out and "generator: aggregate_fraction" in out


@pytest.mark.parametrize("change, message", [
    (lambda t: t.replace('pixel_size = "0.4 mm"\n', ""), "without pixel_size"),
    (lambda t: t.replace('photo = "section.png"\n',
                         'photo = "section.png"\naggregate_fraction = 0.3\n'),
     "together with photo"),
    (lambda t: t.replace("section.png", "nowhere.png"), "does not exist"),
    (lambda t: t.replace('photo = "section.png"\n', ""), "without photo"),
])
def test_photo_keys_are_checked_before_building(tmp_path, change, message):
    from sphdyn.deck import load_deck

    _section_png(tmp_path / "section.png")
    deck = tmp_path / "d.toml"
    deck.write_text(change(PHOTO.format(seed=1)))
    with pytest.raises(DeckError, match=message):
        load_deck(deck)
    deck.write_text(DECK.format(seed=1).replace('max_aggregate_size = "12 mm"\n', ""))
    with pytest.raises(DeckError, match="max_aggregate_size missing"):
        load_deck(deck)
