"""The study scripts' decks and reference values (studies/): cheap checks, no runs."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.model import build_model

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
import formulation_bending as fb  # noqa: E402


@pytest.mark.parametrize("template", ["cantilever.toml.tmpl", "rod.toml.tmpl"])
@pytest.mark.parametrize("form", fb.FORMULATIONS, ids=[f[0] for f in fb.FORMULATIONS])
def test_study_decks_build(template, form):
    label, formulation, correction = form
    deck = loads_deck(fb._deck(template, 6, formulation, correction, label, 1e-5))
    model = build_model(deck)
    x = model.particles.x0
    across = np.unique(np.floor(x[:, 1] / (fb.THICKNESS / 6))).size
    assert across == 6
    assert x[:, 0].max() < fb.LENGTH
    assert deck.sph.correction == (correction == "true")


def test_beam_references():
    """Euler-Bernoulli value, mode shape, and the Timoshenko elements: stiff in
    shear they leave only rotary inertia (a fraction of a percent at L/H = 10)."""
    f_eb = fb.euler_bernoulli_f1()
    assert f_eb == pytest.approx(854.75, rel=1e-4)
    assert fb.mode_shape(np.array([0.0, fb.LENGTH])) == pytest.approx([0.0, 1.0], abs=1e-12)
    assert fb.timoshenko_f1(shear_factor=1e6) == pytest.approx(f_eb, rel=3e-3)
    assert fb.timoshenko_f1() < fb.timoshenko_f1(shear_factor=1e6)
    assert fb.plate_wave_speed() == pytest.approx(math.sqrt(fb.E_PLANE / fb.DENSITY))


def test_zero_crossings_of_a_sine():
    t = np.linspace(0.0, 2.3, 2001)
    tz = fb.zero_crossings(t, np.sin(2 * math.pi * t))
    assert tz == pytest.approx([0.5, 1.0, 1.5, 2.0], abs=1e-5)
