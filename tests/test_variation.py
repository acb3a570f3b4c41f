"""[material.variation]: random scatter of a material parameter (thesis sec. 7.2).

The factor law, the equal-probability classes, the correlated Gaussian field
and the model built from a deck with the ITZ strength varied.
"""

import numpy as np
import pytest
from scipy import stats

from sphdyn.deck import DeckError, loads_deck
from sphdyn.heterogeneity.variation import (FACTOR_FLOOR, factor_of, quantise,
                                            standard_normal_field)
from sphdyn.build.model import build_model

DECK = """
[run]
dimension = 2
t_end = 1e-4
seed = {seed}
[[material]]
name = "mortar"
model = "cscm"
density = 2300.0
fc = "40 MPa"
[[material]]
name = "itz"
model = "cscm"
density = 2200.0
fc = "28 MPa"
{variation}
[[body]]
name = "specimen"
material = "mortar"
dx = 2e-3
geometry = {{ shape = "box", lo = [0, 0], hi = [0.1, 0.1] }}
[body.mesostructure]
aggregate_fraction = 0.3
max_aggregate_size = "16 mm"
itz_thickness = "2 mm"
itz = "itz"
"""


def _model(variation="", seed=1):
    return build_model(loads_deck(DECK.format(seed=seed, variation=variation)))


@pytest.mark.parametrize("law", ["lognormal", "normal"])
def test_factor_has_mean_one_and_the_requested_cov(law):
    # 1e6 standard normal values: the standard error of the mean factor is
    # cov/1000 = 1.5e-4 and that of the sample CoV about cov/1400; 5e-4
    # tolerances are more than 3 standard errors. Lognormal: mean 1 and CoV
    # exactly (s^2 = ln(1 + v^2)); normal: 1 + v z, floored far in the tail.
    z = np.random.default_rng(0).standard_normal(1_000_000)
    f = factor_of(z, 0.15, law)
    assert f.mean() == pytest.approx(1.0, abs=5e-4)
    assert f.std() / f.mean() == pytest.approx(0.15, abs=5e-4)
    if law == "lognormal":
        s = np.sqrt(np.log(1 + 0.15 ** 2))
        assert stats.kstest(f, stats.lognorm(s, scale=np.exp(-s * s / 2)).cdf).pvalue > 1e-3
    assert factor_of(np.array([-100.0]), 0.15, "normal")[0] == FACTOR_FLOOR
    assert np.all(factor_of(z, 0.0, law) == 1.0)  # no scatter: exactly 1


def test_classes_have_equal_probability():
    # 160,000 draws into 16 classes: each count is binomial(N, 1/16), sd 97;
    # 5 sd = 485. The class middles are the normal quantiles (k + 1/2)/16.
    z = np.random.default_rng(1).standard_normal(160_000)
    cls, mids = quantise(z, 16)
    counts = np.bincount(cls, minlength=16)
    assert counts.size == 16 and np.all(np.abs(counts - 10_000) < 485)
    assert np.allclose(stats.norm.cdf(mids), (np.arange(16) + 0.5) / 16)
    assert np.all(np.diff(mids) > 0)
    for k in (0, 7, 15):  # every value lies in its own class's interval
        inside = z[cls == k]
        lo = -np.inf if k == 0 else stats.norm.ppf(k / 16)
        hi = np.inf if k == 15 else stats.norm.ppf((k + 1) / 16)
        assert inside.min() >= lo and inside.max() < hi


def test_correlated_field_is_standard_normal_with_gaussian_correlation():
    # A 60^3 lattice (spacing 1 mm) and ell = 10 mm, four seeds. The field
    # is N(0, 1) at every point by construction (exact normalisation), so
    # the pooled mean and std are 0 and 1 up to the sampling error of a
    # correlated field (~(ell/L)^{3/2} = 0.07 per seed, /2 over four);
    # tolerance 0.1. The correlation at lags 5, 10 and 20 mm follows
    # exp(-(r/ell)^2) = 0.78, 0.37, 0.02 within 0.05 (voxel rounding of
    # ell/4 and the finite sample).
    g = np.mgrid[0:60, 0:60, 0:60].reshape(3, -1).T * 1e-3
    fields = [standard_normal_field(g, 0.01, np.random.default_rng(s)) for s in range(4)]
    z = np.concatenate(fields)
    assert abs(z.mean()) < 0.1 and z.std() == pytest.approx(1.0, abs=0.1)
    for lag in (5, 10, 20):
        r = np.mean([np.corrcoef(f.reshape(60, 60, 60)[:-lag].ravel(),
                                 f.reshape(60, 60, 60)[lag:].ravel())[0, 1]
                     for f in fields])
        assert r == pytest.approx(np.exp(-(lag / 10) ** 2), abs=0.05)
    same = standard_normal_field(g, 0.01, np.random.default_rng(0))
    assert np.array_equal(same, fields[0])  # reproducible from its seed


def test_uncorrelated_and_plane_fields():
    # ell = 0: independent N(0, 1) values (KS); a plane of points (2D
    # bodies have z = 0) gets a 2D field whose neighbours 1 mm apart are
    # correlated exp(-(1/5)^2) = 0.96 for ell = 5 mm (tolerance 0.05).
    rng = np.random.default_rng(2)
    pts = rng.random((20_000, 3))
    assert stats.kstest(standard_normal_field(pts, 0.0, rng), "norm").pvalue > 1e-3
    g = np.mgrid[0:100, 0:100].reshape(2, -1).T * 1e-3
    plane = np.column_stack([g, np.zeros(len(g))])
    f = standard_normal_field(plane, 0.005, rng).reshape(100, 100)
    assert f.std() == pytest.approx(1.0, abs=0.2)
    assert np.corrcoef(f[:-1].ravel(), f[1:].ravel())[0, 1] == pytest.approx(0.96, abs=0.05)


def test_particle_variation_splits_the_itz_into_refitted_classes():
    # The ITZ strength varies per particle in 8 classes; mortar is untouched.
    # Each class is the ITZ material refitted from fc * factor: its packed
    # parameters equal those of a material declared with that fc, and its
    # wave speed follows (CSCM moduli are fitted from fc).
    m = _model('variation = { parameter = "fc", cov = 0.2, classes = 8 }')
    ref = _model()
    p = m.particles
    itz = p.mat == 1
    assert np.array_equal(p.mat, ref.particles.mat)  # same phases
    assert np.all(m.variation[~itz] == 1.0)
    assert len(np.unique(m.variation[itz])) == 8
    # independent particles: the factor's mean and CoV within 4 standard
    # errors of 1 and 0.2 (about 400 ITZ particles; the 8 class values
    # underestimate the CoV by the within-class spread, ~5 %)
    n = int(itz.sum())
    f = m.variation[itz]
    assert n > 300
    assert f.mean() == pytest.approx(1.0, abs=4 * 0.2 / np.sqrt(n))
    assert f.std() / f.mean() == pytest.approx(0.2 * 0.95, rel=0.15)
    model = m.groups[0].model
    for g in m.groups:
        fac = m.variation[g.idx]
        assert np.all(fac == fac[0])
        if g.name == "mortar":
            assert fac[0] == 1.0
            continue
        assert g.name.startswith("itz#")
        single = build_model(loads_deck(DECK.format(seed=1, variation="").replace(
            'fc = "28 MPa"', f"fc = {float(28e6 * fac[0])!r}")))
        expect = next(s.params for s in single.groups if s.name == "itz")
        assert np.allclose(g.params, expect, rtol=1e-12, atol=0)
        assert np.allclose(p.c[g.idx], model.wave_speed(expect, 2200.0))
    assert np.all(p.c[p.mat == 0] == ref.particles.c[p.mat == 0])


def test_sample_variation_gives_one_factor_per_run_with_the_requested_law():
    # scope = "sample": every ITZ particle has the same factor; over 200 run
    # seeds the factors follow the lognormal law of CoV 0.1 (KS, p > 1e-3).
    var = 'variation = { parameter = "fc", cov = 0.1, scope = "sample" }'
    draws = []
    for seed in range(200):
        m = _model(var, seed)
        f = m.variation[m.particles.mat == 1]
        assert np.all(f == f[0])
        assert sum(g.name.startswith("itz") for g in m.groups) == 1
        draws.append(f[0])
    s = np.sqrt(np.log(1 + 0.01))
    assert stats.kstest(draws, stats.lognorm(s, scale=np.exp(-s * s / 2)).cdf).pvalue > 1e-3
    # the same seed gives the same factor, the zero-CoV limit is the plain model
    assert np.array_equal(_model(var, 5).variation, _model(var, 5).variation)
    none = _model('variation = { parameter = "fc", cov = 0.0, scope = "sample" }')
    plain = _model()
    assert [g.name for g in none.groups] == [g.name for g in plain.groups]
    for a, b in zip(none.groups, plain.groups):
        assert np.array_equal(a.params, b.params) and np.array_equal(a.idx, b.idx)


def test_variation_is_an_output_field(tmp_path):
    # The factor per particle is written with the frames (ParaView field
    # "variation"): the model's factors on the ITZ, 1 on the mortar; a run
    # without variation writes 1 everywhere.
    from sphdyn.io import list_frames, read_frame
    from sphdyn.simulation import Simulation

    out = '[output]\nfields = ["variation", "material"]\nprogress = false\n'
    for name, var in (("var", 'variation = { parameter = "fc", cov = 0.2 }'), ("plain", "")):
        deck = loads_deck(DECK.format(seed=1, variation=var) + out)
        sim = Simulation.from_deck(deck, tmp_path / name)
        sim.run(max_steps=1)
        f = read_frame(list_frames(tmp_path / name)[0])[2]
        assert np.array_equal(f["variation"], sim.model.variation)
        assert np.all(f["variation"][f["material"] == 0] == 1.0)
        assert np.any(f["variation"] != 1.0) == (name == "var")


@pytest.mark.parametrize("variation, message", [
    ('variation = { parameter = "fcc", cov = 0.1 }', "not a varied parameter"),
    ('variation = { parameter = "GFT", cov = 0.1 }', "give GFT explicitly"),
    ('variation = { parameter = "density", cov = 0.1 }', "not a varied parameter"),
    ('variation = { parameter = "fc", cov = 0.1, scope = "sample", '
     'correlation_length = "5 mm" }', "remove correlation_length"),
    ('variation = { parameter = "fc", cov = 1.5 }', "cov"),
])
def test_bad_variation_is_rejected_with_a_fix(variation, message):
    with pytest.raises(DeckError, match=message):
        loads_deck(DECK.format(seed=1, variation=variation))
