"""examples/igirder.py's quasi-static curves: the first bending mode's ringing
averaged out, the rest kept (the measure the I-girder's comparison reports)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from sphdyn.interactions.nodal import ramp

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def ig():
    spec = importlib.util.spec_from_file_location("igirder", ROOT / "examples" / "igirder.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _curve(ig, force_of_t, ramp_time=32e-3):
    """A curve (d, F) as igirder.curve gives it: the deck's smooth ramp,
    sampled every 10 us (the decks' history)."""
    t = np.arange(0.0, ramp_time + 1e-12, 1e-5)
    d = np.array([ig.DEPTH * ramp(ti, ramp_time, "smooth") for ti in t])
    return d, force_of_t(t, d)


def test_the_first_mode_ringing_is_averaged_out_and_the_trend_kept(ig):
    # a force linear in d (2 kN/mm) with a 3 kN ringing at the first bending
    # period: the average over that period takes the ringing out (a whole
    # number of its periods; what is left is the sampling's, below 1e-3 of
    # it) and leaves the trend, whose curvature in time over one period moves
    # it by less than 1 % of its largest value (d'' T^2 / 24 over the ramp)
    ringing = 3e3

    def force(t, d):
        return 2e6 * d + ringing * np.sin(2 * np.pi * t / ig.FIRST_MODE)

    d, f = ig.quasi_static(_curve(ig, force), 32e-3)
    half = ig.FIRST_MODE / 2
    t = np.linspace(0.0, 32e-3, 8001)[: d.size]
    inner = (t > half + 1e-4) & (t < 32e-3 - half - 1e-4)
    trend = 2e6 * d
    assert np.max(np.abs(f - trend)[inner]) < 0.01 * trend.max()
    # the ringing alone: out to 1e-3 of its amplitude
    d0, f0 = ig.quasi_static(_curve(ig, lambda t, d: ringing * np.sin(2 * np.pi * t
                                                                      / ig.FIRST_MODE)),
                             32e-3)
    assert np.max(np.abs(f0[inner])) < 1e-3 * ringing
    # without the average (a window of one sample) the ringing stays
    assert ig.moving_average(np.sin(np.arange(10.0)), 1.0) == pytest.approx(
        np.sin(np.arange(10.0)))


def test_the_ramp_time_of_each_model(ig):
    # the half-rate variants ramp over 64 ms; the decks and other variants 32 ms
    assert ig.ramp_time("fem_slow") == pytest.approx(64e-3)
    assert ig.ramp_time("sph_slow") == pytest.approx(64e-3)
    assert ig.ramp_time("fem") == ig.ramp_time("sph_corr") == pytest.approx(32e-3)
