"""Random particle-mass fields (paper sec. 4): total mass, laws, homogeneous limit."""

import numpy as np
import pytest
from scipy import stats

from sphdyn.deck import DeckError, loads_deck
from sphdyn.heterogeneity.mass import (body_rng, distribution, draw_factors,
                                       mass_field)
from sphdyn.heterogeneity.plots import plot_mass_histogram
from sphdyn.io import read_frame
from sphdyn.io.frames import list_frames
from sphdyn.build.model import build_model
from sphdyn.simulation import Simulation

from decks import concrete_disc_2d

LAWS = {
    "uniform": {"distribution": "uniform", "low": 0.0, "high": 2.0},
    "normal": {"distribution": "normal", "mean": 1.0, "std": 0.6},
    "lognormal": {"distribution": "lognormal", "sigma": 0.5},
    "poisson": {"distribution": "poisson", "lam": 3.0},
    "histogram": {"distribution": "histogram", "edges": [0.0, 0.5, 1.0, 2.0],
                  "weights": [1.0, 0.0, 3.0]},
}
ZERO_VARIANCE = [
    {"distribution": "uniform", "low": 1.0, "high": 1.0},
    {"distribution": "normal", "mean": 1.0, "std": 0.0},
    {"distribution": "lognormal", "sigma": 0.0},
]

def _deck(mass: dict | None = None, seed: int = 0):
    if mass is None:
        table = ""
    else:
        items = ", ".join(f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"'
                          for k, v in mass.items())
        table = f"mass = {{ {items} }}"
    return loads_deck(concrete_disc_2d("2.5 mm", "20 us", "10 us",
                                       ["mass", "damage", "velocity", "stress"],
                                       seed=seed, body=table))


@pytest.mark.parametrize("law", list(LAWS))
def test_total_mass_is_the_homogeneous_one(law):
    # 1240 particles of m0 = rho dx^2 = 0.015 kg/m; the rescaled sum differs
    # from N m0 only by the round-off of two sums of 1240 terms: relative
    # error below 1240 * 2.2e-16 ~ 3e-13 (tolerance 1e-12).
    homo = build_model(_deck()).particles
    p = build_model(_deck(LAWS[law])).particles
    m0 = 2400.0 * 0.0025 ** 2
    assert np.all(homo.m == m0)
    assert abs(p.m.sum() - p.n * m0) <= 1e-12 * p.n * m0
    assert p.m.min() >= 0.0 and np.ptp(p.m) > 0.1 * m0
    # density, lattice and smoothing length stay those of the homogeneous body
    # (paper Fig. 4): only the volume m / rho varies
    for name in ("x", "h", "rho", "rho0", "vol0"):
        assert np.array_equal(getattr(p, name), getattr(homo, name)), name


@pytest.mark.parametrize("law", ["uniform", "normal", "lognormal", "histogram"])
def test_drawn_masses_follow_the_requested_law(law):
    # KS test at the 0.1 % level on 20000 draws; the masses divided by
    # m0 * scale are the drawn factors. Seeded, so deterministic. The same
    # test must reject a wrong law (power check: p < 1e-6).
    spec = LAWS[law]
    solid = np.ones(20000, bool)
    m, scale = mass_field(2.0, spec, solid, body_rng(7, 0))
    f = m / (2.0 * scale)
    assert stats.kstest(f, distribution(spec).cdf).pvalue > 1e-3
    wrong = stats.norm(1.0, 0.3) if law != "normal" else stats.uniform(0, 2)
    assert stats.kstest(f, wrong.cdf).pvalue < 1e-6
    # rescaling s = N / sum f = 1 / mean(f) + O(N^-1/2): within 4 standard
    # errors of the sample mean (central limit theorem)
    law_ = distribution(spec)
    assert abs(scale * law_.mean() - 1.0) < 4 * law_.std() / law_.mean() / np.sqrt(f.size)


def test_poisson_masses_follow_the_poisson_law():
    # Discrete law: chi-square goodness of fit of the counts k = lam f
    # (classes k = 0..7 and >= 8) at the 0.1 % level; zero counts are
    # zero-mass particles ("pores").
    spec = LAWS["poisson"]
    m, scale = mass_field(1.0, spec, np.ones(20000, bool), body_rng(3, 1))
    k = np.rint(m / scale * spec["lam"]).astype(int)
    assert np.allclose(k, m / scale * spec["lam"], atol=1e-9)
    obs = np.bincount(np.minimum(k, 8), minlength=9)
    law = distribution(spec)
    p = np.append(law.pmf(np.arange(8)), law.sf(7))
    assert stats.chisquare(obs, p * k.size).pvalue > 1e-3
    assert (m == 0).sum() == obs[0] > 0


@pytest.mark.parametrize("spec", ZERO_VARIANCE, ids=lambda s: s["distribution"])
def test_zero_variance_law_is_bitwise_the_homogeneous_body(spec):
    homo = build_model(_deck()).particles
    p = build_model(_deck(spec)).particles
    assert np.array_equal(p.m, homo.m)


def test_zero_variance_run_reproduces_the_deterministic_run(tmp_path):
    # The whole run, not only the masses: every output field bitwise equal.
    out = {}
    for name, spec in (("homo", None), ("flat", ZERO_VARIANCE[0])):
        Simulation.from_deck(_deck(spec), tmp_path / name).run()
        out[name] = read_frame(list_frames(tmp_path / name)[-1])[2]
    for key in out["homo"]:
        assert np.array_equal(out["homo"][key], out["flat"][key]), key


def test_seed_makes_the_field_reproducible():
    a = build_model(_deck(LAWS["uniform"], seed=1)).particles.m
    b = build_model(_deck(LAWS["uniform"], seed=1)).particles.m
    c = build_model(_deck(LAWS["uniform"], seed=2)).particles.m
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    # the stream of each body is its own: body index enters the seed
    f0 = draw_factors(LAWS["uniform"], 100, body_rng(1, 0))
    f1 = draw_factors(LAWS["uniform"], 100, body_rng(1, 1))
    assert not np.allclose(f0, f1)


def test_bad_mass_tables_are_rejected_with_the_fix():
    with pytest.raises(DeckError) as err:
        _deck({"distribution": "uniform", "low": 0.0, "std": 1.0})
    assert "missing high" in str(err.value) and "not used: std" in str(err.value)
    with pytest.raises(DeckError, match="high >= low"):
        _deck({"distribution": "uniform", "low": 2.0, "high": 1.0})
    with pytest.raises(DeckError, match="one non-negative weight per bin"):
        _deck({"distribution": "histogram", "edges": [0.0, 1.0], "weights": [1.0, 2.0]})
    with pytest.raises(DeckError, match="increasing"):
        _deck({"distribution": "histogram", "edges": [1.0, 0.0], "weights": [1.0]})


def test_mass_field_output_and_histogram_plot(tmp_path):
    # The mass field is an output field (paper Fig. 6) and its histogram a
    # plot (Fig. 5).
    deck = _deck(LAWS["uniform"], seed=5)
    sim = Simulation.from_deck(deck, tmp_path / "run")
    sim.run(max_steps=1)
    fields = read_frame(list_frames(tmp_path / "run")[0])[2]
    assert np.array_equal(fields["mass"], sim.particles.m)
    m0 = 2400.0 * 0.0025 ** 2
    m, scale = mass_field(m0, LAWS["uniform"], np.ones(sim.particles.n, bool),
                          body_rng(5, 0))
    assert np.array_equal(m, sim.particles.m)
    png = plot_mass_histogram(m, tmp_path / "hist.png", law=distribution(LAWS["uniform"]),
                              scale=scale, m0=m0)
    assert png.stat().st_size > 5000
