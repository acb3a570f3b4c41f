"""Swegle et al. (1995) tensile-instability indicator (sphdyn.parts.sph.swegle)."""

import numpy as np
import pytest

from sphdyn import kernels
from sphdyn.deck import loads_deck
from sphdyn.geometry import box_lattice
from sphdyn.io import particle_fields
from sphdyn.neighbours import build_neighbours
from stepping import build_stepper
from sphdyn.parts.sph.swegle import (FLAG_FRACTION, REL_STRESS_TOL, count_unstable, stress_scale,
                               swegle_indicator)

DX = 1e-3
S = 1.0e6


def _indicator(x, h, sig, kernel="cubic_spline", dim=2, m=None, tol=None):
    n = x.shape[0]
    kid = kernels.kernel_id(kernel)
    m = np.ones(n) if m is None else m
    nl = build_neighbours(x, h, kernels.support(kid), 0.0, dim)
    out = np.full(n, -1.0)
    tol = REL_STRESS_TOL * stress_scale(sig, m) if tol is None else tol
    swegle_indicator(x, m, h, sig, nl.offsets, nl.idx, kid, kernels.normalisation(kid, dim),
                     dim, 1.0, tol, out)
    return out


def _lattice(hfac=1.2, n_side=10):
    x = box_lattice([0, 0, 0], [n_side * DX, n_side * DX, 0], DX, 2)
    return x, np.full(x.shape[0], hfac * DX)


def _interior(x, margin=3 * DX):
    lo, hi = x[:, :2].min(axis=0), x[:, :2].max(axis=0)
    return np.all((x[:, :2] > lo + margin - 1e-12) & (x[:, :2] < hi - margin + 1e-12),
                  axis=1)


def _uniform(n, sxx=0.0, syy=0.0, sxy=0.0):
    sig = np.zeros((n, 3, 3))
    sig[:, 0, 0] = sxx
    sig[:, 1, 1] = syy
    sig[:, 0, 1] = sig[:, 1, 0] = sxy
    return sig


def test_cubic_spline_second_derivative_changes_sign_at_two_thirds():
    # the premise of the lattice tests: W'' < 0 for q < 2/3, > 0 beyond (cubic spline)
    assert kernels.d2wdq2(0, 0.6) < 0.0 < kernels.d2wdq2(0, 0.7)
    assert kernels.d2wdq2(0, 1.0 / 1.2) > 0.0


def test_uniaxial_tension_flags_pairs_with_a_component_along_the_axis():
    # square lattice, h = 1.2 dx: the 20 interior neighbours (r < 2.4 dx) are
    # at q = 0.83, 1.18, 1.67, 1.86, all with W'' > 0; under sigma_xx > 0 the
    # 16 pairs with n_x != 0 have sigma_n = sigma_xx n_x^2 > 0 (unstable),
    # the 4 along y have sigma_n = 0: indicator exactly 16/20
    x, h = _lattice()
    s = _indicator(x, h, _uniform(x.shape[0], sxx=S))
    inner = _interior(x)
    assert inner.sum() > 10
    assert np.allclose(s[inner], 0.8, rtol=0, atol=1e-12)
    assert np.all(s > FLAG_FRACTION)  # edge particles too: >= 50 % of pairs have n_x != 0
    assert count_unstable(s, np.ones_like(s), FLAG_FRACTION) == x.shape[0]


@pytest.mark.parametrize("sig", [dict(sxx=-S), dict(sxx=-S, syy=-0.5 * S), dict()])
def test_compression_and_zero_stress_flag_nothing(sig):
    x, h = _lattice()
    s = _indicator(x, h, _uniform(x.shape[0], **sig))
    assert np.all(s == 0.0)


def test_pure_shear_flags_the_tensile_diagonal_only():
    # sigma_xy = tau: sigma_n = 2 tau n_x n_y > 0 for pairs along (1, 1), < 0 along
    # (1, -1), 0 on the axes. Interior: 6 of 20 neighbours have n_x n_y > 0,
    # offsets (1, 1), (1, 2), (2, 1) and their negatives
    x, h = _lattice()
    s = _indicator(x, h, _uniform(x.shape[0], sxy=S))
    assert np.allclose(s[_interior(x)], 6 / 20, rtol=0, atol=1e-12)


def test_sign_of_w2_matters_not_only_the_stress():
    # two particles dx apart along x: with h = 1.2 dx (q = 0.83, W'' > 0) tension
    # is unstable; with h = 2 dx (q = 0.5, W'' < 0) compression is unstable instead
    x = np.array([[0.0, 0, 0], [DX, 0, 0]])
    tension = _uniform(2, sxx=S)
    compression = _uniform(2, sxx=-S)
    assert np.all(_indicator(x, np.full(2, 1.2 * DX), tension) == 1.0)
    assert np.all(_indicator(x, np.full(2, 1.2 * DX), compression) == 0.0)
    assert np.all(_indicator(x, np.full(2, 2.0 * DX), tension) == 0.0)
    assert np.all(_indicator(x, np.full(2, 2.0 * DX), compression) == 1.0)
    # tension across the pair (sigma_yy) gives sigma_n = 0: not flagged
    assert np.all(_indicator(x, np.full(2, 1.2 * DX), _uniform(2, syy=S)) == 0.0)


def test_round_off_stress_is_ignored_and_zero_mass_neighbours_skipped():
    x, h = _lattice(n_side=6)
    n = x.shape[0]
    sig = _uniform(n, sxx=-S)
    sig[0, 0, 0] = 1e-6 * S  # tiny tension, below REL_STRESS_TOL of the max stress
    assert _indicator(x, h, sig)[0] == 0.0
    # all neighbours of particle 0 massless: no pairs, indicator 0 (a
    # massless particle itself is still evaluated against massive neighbours)
    m = np.zeros(n)
    m[0] = 1.0
    s = _indicator(x, h, _uniform(n, sxx=S), m=m)
    assert s[0] == 0.0
    assert s[1:].max() == 1.0


def test_round_off_stress_before_any_load_flags_nothing():
    """Every stress at round-off (micropascals: a body in free flight whose
    velocities differ in the last bit) and some pairs in tension: the
    threshold is STRAIN_FLOOR x rho c^2 (here 1e-9 x 2400 x 3600^2 = 31 Pa),
    not REL_STRESS_TOL of the round-off itself, so nothing is flagged; a
    real tension of 1 kPa is."""
    from sphdyn.parts.sph.swegle import STRAIN_FLOOR, stress_tolerance

    x, h = _lattice(n_side=6)
    n = x.shape[0]
    m, rho, c = np.ones(n), np.full(n, 2400.0), np.full(n, 3600.0)
    sig = _uniform(n, sxx=1e-6)
    tol = stress_tolerance(sig, m, rho, c)
    assert tol == pytest.approx(STRAIN_FLOOR * 2400.0 * 3600.0 ** 2, rel=1e-15)
    assert REL_STRESS_TOL * stress_scale(sig, m) < 1e-8  # the relative test alone
    assert _indicator(x, h, sig, tol=tol).max() == 0.0
    assert _indicator(x, h, sig, tol=REL_STRESS_TOL * stress_scale(sig, m)).max() > 0.0
    loaded = _uniform(n, sxx=1e3)
    assert _indicator(x, h, loaded, tol=stress_tolerance(loaded, m, rho, c)).max() > 0.0


DECK = """
[run]
dimension = 2
t_end = 1e-4
[[material]]
name = "m"
model = "elastic"
density = 1000.0
E = 1.0e7
nu = 0.3
[[body]]
name = "b"
material = "m"
dx = 0.001
geometry = { shape = "box", lo = [0, 0], hi = [0.01, 0.01] }
[output]
fields = ["swegle"]
"""


def test_solver_output_field_and_history_column():
    d = loads_deck(DECK)
    s = build_stepper(d)
    s.part("sph").kin.sig[:] = _uniform(s.part("sph").kin.n, sxx=S)
    f = particle_fields(s.part("sph").kin, ["swegle"], s.part("sph").fields())["swegle"]
    assert f.shape == (s.part("sph").kin.n,)
    assert np.all(f > FLAG_FRACTION)
    rec = s.record(kinetic=0.0, dt=0.0)
    assert rec["swegle_unstable"] == s.part("sph").kin.n
    # the field is a copy; a stress-free state after a step flags nothing
    f[:] = -1.0
    s.part("sph").kin.sig[:] = 0.0
    s.part("sph").kin.v[:] = 0.0
    s.step()
    s.part("sph").kin.sig[:] = 0.0
    assert np.all(particle_fields(s.part("sph").kin, ["swegle"], s.part("sph").fields())["swegle"] == 0.0)
    assert s.record(kinetic=0.0, dt=0.0)["swegle_unstable"] == 0.0


def test_quadratic_kernel_is_stable_in_compression_at_any_spacing():
    # Johnson et al. (1996): w'' = 3/8 > 0 on the whole support, so compressed
    # particles (here h = 2.5 dx: the nearest neighbours at q = 0.4, where
    # the cubic spline has W'' < 0 and compression is unstable) are never
    # flagged with the quadratic kernel, while tension is flagged.
    assert all(kernels.d2wdq2(kernels.kernel_id("quadratic"), q) > 0
               for q in np.linspace(0.0, 1.99, 50))
    x, h = _lattice(hfac=2.5, n_side=14)
    comp = _uniform(x.shape[0], sxx=-S, syy=-S)
    inner = _interior(x, margin=6 * DX)
    assert np.all(_indicator(x, h, comp, kernel="quadratic")[inner] == 0.0)
    assert np.all(_indicator(x, h, comp, kernel="cubic_spline")[inner] > 0.0)
    tens = _uniform(x.shape[0], sxx=S, syy=S)
    assert np.all(_indicator(x, h, tens, kernel="quadratic")[inner] == 1.0)
