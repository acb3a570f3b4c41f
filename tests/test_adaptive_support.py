"""Support size adapted to the local spacing (sph.smoothing_length.initial = "adaptive")."""

import numpy as np
import pytest

from sphdyn import kernels
from sphdyn.deck import loads_deck
from sphdyn.geometry import box_lattice
from sphdyn.geometry.spacing import adapted_smoothing_lengths, local_spacing
from sphdyn.build.model import build_model
from sphdyn.neighbours import build_neighbours
from decks import STEEL


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_spacing_is_dx_everywhere(dim):
    # the dim-th nearest neighbour sits at dx inside, on faces, edges and at
    # corners of a lattice (1e-12: round-off of the distances)
    dx = 0.01
    x = box_lattice([0, 0, 0], [0.06, 0.05, 0.04], dx, dim)
    assert np.allclose(local_spacing(x, dim), dx, rtol=1e-12)


L = 0.12  # side of each half [m]


def _mixed_cloud(dim, dx=0.01, seed=0):
    """A coarse lattice (dx) left of x = L and a fine one (dx/2) right of it,
    the fine one jittered by 10 % of its spacing: a refined, irregular region."""
    coarse = box_lattice([0, 0, 0], [L, L, L], dx, dim)
    fine = box_lattice([L, 0, 0], [2 * L, L, L], dx / 2, dim)
    rng = np.random.default_rng(seed)
    fine[:, :dim] += 0.1 * dx / 2 * rng.uniform(-1, 1, (fine.shape[0], dim))
    x = np.vstack([coarse, fine])
    fine_mask = np.arange(x.shape[0]) >= coarse.shape[0]
    return x, fine_mask


def _inside(x, dim, margin):
    """Particles at least ``margin`` inside the outer boundary of the cloud."""
    ok = np.ones(x.shape[0], bool)
    for a in range(dim):
        ok &= (x[:, a] > margin) & (x[:, a] < (2 * L if a == 0 else L) - margin)
    return ok


def _counts(x, h, dim, kid):
    nl = build_neighbours(x, h, kernels.support(kid), 0.0, dim)
    n = x.shape[0]
    count = np.zeros(n, int)
    q = kernels.support(kid)
    for i in range(n):
        j = nl.idx[nl.offsets[i]:nl.offsets[i + 1]]
        r = np.linalg.norm(x[j] - x[i], axis=1)
        count[i] = np.count_nonzero(r < q * 0.5 * (h[i] + h[j]))
    return count


@pytest.mark.parametrize("dim", [2, 3])
def test_adapted_support_keeps_the_neighbour_count_in_a_refined_region(dim):
    # With one h for the whole region (the coarse body's), particles of the
    # refined half see ~2^dim times the neighbours; adapted to the local
    # spacing, interior particles of both halves see the same count within
    # 25 % (the jitter moves a few across the support edge; the nominal count
    # is off by a factor 4 in 2D, 8 in 3D, so the test can fail).
    dx, eta = 0.01, 1.3
    kid = kernels.kernel_id("cubic_spline")
    x, fine = _mixed_cloud(dim, dx)
    margin = kernels.support(kid) * eta * dx  # one coarse support
    inner = _inside(x, dim, margin)
    inner &= np.abs(x[:, 0] - L) > margin  # away from the spacing jump
    assert (inner & fine).sum() > 10 and (inner & ~fine).sum() > 10
    nominal = np.full(x.shape[0], eta * dx)
    c_nom = _counts(x, nominal, dim, kid)
    ratio_nom = c_nom[inner & fine].mean() / c_nom[inner & ~fine].mean()
    assert ratio_nom > 0.8 * 2**dim
    h = adapted_smoothing_lengths(x, nominal, eta, dim, 0.2, 2.0, kernels.support(kid))
    c = _counts(x, h, dim, kid)
    ratio = c[inner & fine].mean() / c[inner & ~fine].mean()
    assert abs(ratio - 1.0) < 0.25
    assert np.allclose(h[inner & ~fine], eta * dx, rtol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_adapted_support_partition_of_unity_across_the_jump(dim):
    # Shepard sum sum_j V_j W_ij (h_ij = mean) within 12 % of 1 at every
    # particle one coarse support inside the outer boundary, the spacing
    # jump included. Measured 10.1 % (2D), 7.6 % (3D); the jitter alone
    # costs 7.6 % / 7.2 % with the exact per-region h, which reaches 14.6 %
    # / 11.5 % at the jump (sphdyn.geometry.spacing). The raw spacing
    # estimate without the averaging pass gives 15 % / 13 %: a bound the
    # adapted support must beat.
    dx, eta = 0.01, 1.3
    kid = kernels.kernel_id("cubic_spline")
    sig = kernels.normalisation(kid, dim)
    x, fine = _mixed_cloud(dim, dx)
    vol = np.where(fine, (dx / 2) ** dim, dx**dim)
    h = adapted_smoothing_lengths(x, np.full(x.shape[0], eta * dx), eta, dim, 0.2, 2.0,
                                  kernels.support(kid))
    q = kernels.support(kid)
    inner = _inside(x, dim, q * eta * dx)
    assert (inner & fine).sum() > 10 and (inner & ~fine).sum() > 10
    assert np.abs(x[inner, 0] - L).min() < dx  # the jump is among them
    nl = build_neighbours(x, h, q, 0.0, dim)
    for i in np.flatnonzero(inner):
        j = nl.idx[nl.offsets[i]:nl.offsets[i + 1]]
        j = np.append(j, i)
        hij = 0.5 * (h[i] + h[j])
        r = np.linalg.norm(x[j] - x[i], axis=1)
        w = np.array([kernels.kernel_value(kid, sig, dim, rr, hh) for rr, hh in zip(r, hij)])
        assert abs((vol[j] * w).sum() - 1.0) < 0.12


def _deck(initial: str, fine_dx: str = "5 mm") -> str:
    return f"""
[run]
dimension = 2
t_end = "1 us"
[sph]
h_factor = 1.3
[sph.smoothing_length]
initial = "{initial}"
min_factor = 0.4
{STEEL}[[body]]
name = "coarse"
material = "steel"
dx = "10 mm"
geometry = {{ shape = "box", lo = [0, 0], hi = ["100 mm", "100 mm"] }}
[[body]]
name = "fine"
material = "steel"
dx = "{fine_dx}"
geometry = {{ shape = "box", lo = ["100 mm", 0], hi = ["200 mm", "100 mm"] }}
"""


def test_deck_adaptive_support_follows_each_region():
    # two lattices of one material, 10 and 5 mm: each keeps its nominal h
    # (1e-12) more than one support (2 h = 26 mm) from the seam; the coarse
    # particles next to the seam, whose supports reach the fine ones, get a
    # smaller support, within the bounds; h0 is the adapted h.
    nominal = build_model(loads_deck(_deck("nominal"))).particles
    p = build_model(loads_deck(_deck("adaptive"))).particles
    assert np.array_equal(p.x, nominal.x)
    seam = np.abs(p.x[:, 0] - 0.1) < 0.026
    assert np.count_nonzero(~seam) > 100
    assert np.allclose(p.h[~seam], nominal.h[~seam], rtol=1e-12)
    coarse_seam = (np.abs(p.x[:, 0] - 0.1) < 0.0101) & (p.body == 0)
    assert np.all(p.h[coarse_seam] < nominal.h[coarse_seam])
    assert np.all(p.h >= 0.4 * nominal.h - 1e-15)
    assert np.array_equal(p.h0, p.h)


def test_adapted_support_stays_within_the_bounds():
    # h within [min_factor, max_factor] times the nominal h (HMIN/HMAX):
    # the refined half (spacing dx/2) is pinned at 0.8 x nominal when the
    # lower bound is 0.8, and with a nominal h a quarter of eta dx every
    # particle is pinned at max_factor x nominal.
    dx, eta, q = 0.01, 1.3, 2.0
    x, fine = _mixed_cloud(2, dx)
    nominal = np.full(x.shape[0], eta * dx)
    h = adapted_smoothing_lengths(x, nominal, eta, 2, 0.8, 2.0, q)
    assert np.allclose(h[fine], 0.8 * nominal[fine], rtol=1e-12)
    assert np.all(h[~fine] <= nominal[~fine] * (1 + 1e-12))
    small = nominal / 4
    h = adapted_smoothing_lengths(x, small, eta, 2, 0.5, 1.5, q)
    assert np.allclose(h, 1.5 * small, rtol=1e-12)
