"""Tests of the cell-list / Verlet-list neighbour search (sphdyn.neighbours).

Reference solutions
-------------------
* ``brute_force_neighbours``: all N^2 pairs in NumPy with the same
  floating-point pair test; the cell list must reproduce it *exactly*
  (``offsets`` and ``idx`` bitwise equal). Exact equality is the right
  tolerance: the test is a comparison of identically computed numbers, so any
  difference is a missed or spurious pair, i.e. a bug.
* ``scipy.spatial.cKDTree`` as an independent candidate generator
  (``query_pairs`` / ``query_ball_point`` with the largest possible radius,
  padded by a relative 1e-9 so that kd-tree rounding at the cut-off cannot
  drop a candidate), each candidate pair then checked against its own
  h-dependent radius. Again exact set equality.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
from scipy.spatial import cKDTree

from sphdyn.neighbours import (NeighbourList, brute_force_neighbours,
                               build_neighbours, max_displacement,
                               max_neighbours, mean_neighbours, needs_rebuild,
                               update_neighbours)

RF = 2.0  # radius_factor (cubic spline support 2 x support scale 1)


# ---------------------------------------------------------------- helpers

def pair_test(x, h, i, j, rf, skin, dim):
    """The documented pair test on index arrays ``i``, ``j`` (vectorised)."""
    d0 = x[i, 0] - x[j, 0]
    d1 = x[i, 1] - x[j, 1]
    d2 = d0 * d0 + d1 * d1
    if dim == 3:
        dz = x[i, 2] - x[j, 2]
        d2 = d2 + dz * dz
    r = (rf * 0.5) * (h[i] + h[j]) + skin
    return d2 < r * r


def csr_from_pairs(n, pi, pj):
    """CSR (offsets, idx) with rows sorted ascending from directed pairs."""
    order = np.lexsort((pj, pi))
    pi, pj = pi[order], pj[order]
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(pi, minlength=n), out=offsets[1:])
    return offsets, pj.astype(np.int32)


def kdtree_neighbours(x, h, rf, skin, dim, active=None, ball=False):
    """Independent reference: cKDTree candidates + per-pair radius check."""
    n = x.shape[0]
    ids = np.arange(n) if active is None else np.flatnonzero(active)
    if ids.size < 2:
        return csr_from_pairs(n, np.empty(0, int), np.empty(0, int))
    tree = cKDTree(x[ids, :dim])
    hmax = h[ids].max()
    if ball:
        # per-particle radius: the largest pair radius particle i can have
        r_i = rf * 0.5 * (h[ids] + hmax) + skin
        lists = tree.query_ball_point(x[ids, :dim], r_i * (1 + 1e-9))
        a = np.concatenate([np.full(len(l), k) for k, l in enumerate(lists)])
        b = np.concatenate([np.asarray(l, dtype=int) for l in lists])
        keep = a != b
        pi, pj = ids[a[keep]], ids[b[keep]]
    else:
        p = tree.query_pairs((rf * hmax + skin) * (1 + 1e-9),
                             output_type="ndarray")
        pi = np.concatenate((ids[p[:, 0]], ids[p[:, 1]]))
        pj = np.concatenate((ids[p[:, 1]], ids[p[:, 0]]))
    ok = pair_test(x, h, pi, pj, rf, skin, dim)
    return csr_from_pairs(n, pi[ok], pj[ok])


def pair_set(offsets, idx):
    """Set of directed pairs (i, j) of a CSR list."""
    rows = np.repeat(np.arange(offsets.shape[0] - 1), np.diff(offsets))
    return set(zip(rows.tolist(), idx.tolist()))


def assert_same(nl, ref, what=""):
    off, idx = ref
    assert nl.offsets.dtype == np.int64 and nl.idx.dtype == np.int32
    np.testing.assert_array_equal(nl.offsets, off, err_msg=f"offsets {what}")
    np.testing.assert_array_equal(nl.idx, idx, err_msg=f"idx {what}")


def assert_well_formed(nl):
    """Sorted rows, no self entries, exact symmetry."""
    n = nl.n
    rows = np.repeat(np.arange(n), np.diff(nl.offsets))
    cols = nl.idx.astype(np.int64)
    assert np.all(rows != cols), "self entry in a row"
    same_row = rows[1:] == rows[:-1]
    assert np.all(cols[1:][same_row] > cols[:-1][same_row]), "row not sorted"
    fwd = rows * n + cols
    bwd = cols * n + rows
    np.testing.assert_array_equal(np.sort(fwd), np.sort(bwd))


def random_cloud(rng, n, dim, h0=0.05, h_ratio=1.0):
    x = rng.random((n, 3))
    x[:, dim:] = 0.0  # 2D: z = 0; 1D (along x): y = z = 0
    h = h0 * h_ratio ** rng.random(n)  # log-uniform in [h0, h0 * h_ratio]
    return x, h


# ---------------------------------------------------------------- tests

@pytest.mark.parametrize("dim", [1, 2, 3])
def test_random_cloud_matches_brute_force_and_kdtree(dim):
    rng = np.random.default_rng(10 + dim)
    n = {1: 800, 2: 1500, 3: 2500}[dim]
    x, h = random_cloud(rng, n, dim, h0={1: 0.005, 2: 0.02, 3: 0.04}[dim],
                        h_ratio=2.0)
    skin = 0.1 * h.min()
    nl = build_neighbours(x, h, RF, skin, dim)
    ref = brute_force_neighbours(x, h, RF, skin, dim)
    assert_same(nl, ref, "vs brute force")
    assert_same(nl, kdtree_neighbours(x, h, RF, skin, dim), "vs query_pairs")
    assert_well_formed(nl)
    # non-trivial lists (guards against comparing empty lists)
    assert 10 < mean_neighbours(nl) < 100
    assert max_neighbours(nl) == np.diff(ref[0]).max()
    assert mean_neighbours(nl) == pytest.approx(ref[0][-1] / n, rel=0, abs=0)
    assert nl.n_builds == 1 and nl.skin == skin and nl.radius_factor == RF
    np.testing.assert_array_equal(nl.x_ref, x)
    assert nl.x_ref is not x and nl.h_ref is not h


def test_cubic_lattice_ties_are_excluded():
    """Integer lattice, dx = 1, h = 1, rf = 2, skin = 0: radius exactly 2.

    Distances are exact in floating point, so |v|^2 == 4 pairs sit exactly
    on the radius: the strict '<' excludes them. An interior particle has
    the 6 + 12 + 8 = 26 neighbours with |v|^2 in {1, 2, 3}; with '<=' it
    would have 32.
    """
    m = 9
    g = np.arange(m, dtype=float)
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    h = np.ones(len(x))
    nl = build_neighbours(x, h, RF, 0.0, 3)
    assert_same(nl, brute_force_neighbours(x, h, RF, 0.0, 3))
    assert_same(nl, kdtree_neighbours(x, h, RF, 0.0, 3))
    centre = (4 * m + 4) * m + 4
    assert np.array_equal(x[centre], [4, 4, 4])
    assert nl.row(centre).size == 26
    d2 = ((x[nl.row(centre)] - x[centre]) ** 2).sum(1)
    assert set(d2) == {1.0, 2.0, 3.0}
    # every interior particle has 26; the tie partner (6, 4, 4) is excluded
    assert (6 * m + 4) * m + 4 not in nl.row(centre)
    interior = np.all((x >= 2) & (x <= m - 3), axis=1)
    assert np.all(np.diff(nl.offsets)[interior] == 26)
    # a tiny skin makes the ties neighbours: 32 = 26 + 6
    nl2 = build_neighbours(x, h, RF, 1e-9, 3)
    assert nl2.row(centre).size == 32


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_inexact_spacing(dim):
    """dx = 0.1 (inexact): ties are decided by rounding, identically in all
    code paths; h = 1.2 dx, skin = 0.24 dx as in production."""
    dx = 0.1
    m = 24 if dim == 2 else 12
    g = np.arange(m) * dx
    if dim == 2:
        xx = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
        x = np.column_stack((xx, np.zeros(len(xx))))
    else:
        x = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    h = np.full(len(x), 1.2 * dx)
    skin = 0.24 * dx
    nl = build_neighbours(x, h, RF, skin, dim)
    assert_same(nl, brute_force_neighbours(x, h, RF, skin, dim))
    assert_same(nl, kdtree_neighbours(x, h, RF, skin, dim))


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_h_varying_by_factor_10(dim):
    """Log-uniform h over a factor 10 (split into a fine and a coarse grid)
    checked with per-particle query_ball_point radii."""
    rng = np.random.default_rng(20 + dim)
    n = 2000
    x, h = random_cloud(rng, n, dim, h0=0.004 if dim == 2 else 0.01,
                        h_ratio=10.0)
    skin = 0.002
    nl = build_neighbours(x, h, RF, skin, dim)
    assert_same(nl, brute_force_neighbours(x, h, RF, skin, dim))
    assert_same(nl, kdtree_neighbours(x, h, RF, skin, dim, ball=True))
    assert_well_formed(nl)
    assert nl.n_big > 0
    if dim > 1:  # on a line the row lengths grow only as h, not h^dim
        assert max_neighbours(nl) > 3 * mean_neighbours(nl) > 0


@pytest.mark.parametrize("dim", [2, 3])
def test_few_large_h_particles_use_big_list(dim):
    """10 particles with 10x h go to the coarse grid (the fine grid's cells
    sized by the bulk), rows of the big particles exceed 128 entries
    (heap-sort path)."""
    rng = np.random.default_rng(30 + dim)
    n = 4000
    x, h = random_cloud(rng, n, dim, h0=0.012 if dim == 2 else 0.025)
    big = rng.choice(n, 10, replace=False)
    h[big] *= 10.0
    skin = 0.001
    nl = build_neighbours(x, h, RF, skin, dim)
    assert nl.n_big == 10
    # cell size follows the small particles, not the large ones
    assert nl.cell_size < 1.0001 * (RF * h.min() + skin)
    assert_same(nl, brute_force_neighbours(x, h, RF, skin, dim))
    assert_same(nl, kdtree_neighbours(x, h, RF, skin, dim, ball=True))
    assert_well_formed(nl)
    assert np.diff(nl.offsets)[big].max() > 128


@pytest.mark.parametrize("dim", [2, 3])
def test_many_large_h_particles_use_coarse_grid(dim):
    """The blast slab's case: ~7 % of the particles (an explosive's products)
    with h 1.1-1.55x the bulk's (3D), clustered in one corner, and a few far
    outside the bulk's box (cell indices clamped) and next to it. They go to
    the coarse grid (more than the 64 the single grid once set aside); the
    fine grid's cells follow the bulk (1.5^dim fewer candidates per cell).
    In 2D the split pays less (the square, not the cube, of the radius
    ratio, against the cost of the second grid's rows): h 1.1-2.0x there."""
    rng = np.random.default_rng(50 + dim)
    n = 6000
    x, h = random_cloud(rng, n, dim, h0=0.015 if dim == 2 else 0.04)
    spread = 0.45 if dim == 3 else 0.9
    prod = np.flatnonzero((x[:, :dim] < 0.4).all(axis=1))[:400]
    h[prod] *= 1.1 + spread * rng.random(prod.size)
    far = rng.choice(np.setdiff1d(np.arange(n), prod), 12, replace=False)
    x[far[:6], 0] = 3.0 + 0.01 * np.arange(6)   # far away, among themselves
    x[far[6:], 0] = -0.02 * np.arange(1, 7)     # just outside, near the bulk
    h[far] *= 1.1 + spread
    skin = 0.1 * h.min()
    nl = build_neighbours(x, h, RF, skin, dim)
    big = h > h[np.setdiff1d(np.arange(n), np.r_[prod, far])].max()
    assert nl.n_big == big.sum() > 64
    assert nl.cell_size < 1.0001 * (RF * h[~big].max() + skin)
    assert_same(nl, brute_force_neighbours(x, h, RF, skin, dim))
    assert_same(nl, kdtree_neighbours(x, h, RF, skin, dim, ball=True))
    assert_well_formed(nl)
    # the far ones find each other, the near ones the bulk's particles
    assert np.isin(nl.row(far[0]), far[:6]).all() and nl.row(far[0]).size
    assert (~big[nl.row(far[6])]).any()


def test_split_by_h_taken_only_where_it_pays():
    """One grid when h is uniform, varies by less than 5 % in pair radius,
    or when the split's estimated gain is below 25 % (h log-uniform over a
    factor 2: the estimate promises ~2 %, the build measured 10 % slower
    split); the split's cost estimate against its formula."""
    from sphdyn.neighbours.grid import _choose_h_cut, _split_cost
    rng = np.random.default_rng(60)
    xa = rng.random((5000, 3))   # positions: a unit cube
    h = np.full(5000, 0.02)
    assert _choose_h_cut(h, xa, RF, 0.0, 3) == (0.02, None)
    h = 0.02 * (1.0 + 0.04 * rng.random(5000))
    assert _choose_h_cut(h, xa, RF, 0.0, 3)[1] is None
    h = 0.02 * 2.0 ** rng.random(5000)
    assert _choose_h_cut(h, xa, RF, 0.0, 3)[1] is None
    h = np.full(5000, 0.02)
    h[:100] = 0.05
    h_cut, mask = _choose_h_cut(h, xa, RF, 0.001, 3)
    assert h_cut == 0.02 and mask.sum() == 100 and mask[:100].all()
    # n = 1000, 100 big; cells 0.041 (fine) and 0.101 (coarse) in a unit box
    n, nb, rf, skin, hc, hm = 1000, 100, 2.0, 0.001, 0.02, 0.05
    r_f, r_c = rf * hc + skin, rf * hm + skin
    occ_f, occ_c = (n - nb) * r_f**3, nb * r_c**3
    k = np.ceil((0.5 * rf * (hm + hc) + skin) / r_f)   # 2
    want = ((n - nb) * (27 * occ_f + 9 * 4.0)
            + nb * ((2 * k + 1)**3 * occ_f + (2 * k + 1)**2 * 4.0)
            + n * (27 * occ_c + 9 * 4.0))
    got = _split_cost(n, np.array([nb, 0.0]), np.array([hc, hm]), hm, rf,
                      skin, 3, 1.0)
    assert got[0] == pytest.approx(want, rel=1e-12)
    assert got[1] == pytest.approx(n * (27 * n * r_c**3 + 9 * 4.0),
                                   rel=1e-12)


def test_dense_rows_longer_than_block_and_rank_sort_limit():
    """~ 250 neighbours per particle: x-runs longer than the 64-candidate
    block of the fill pass and rows sorted by the heap-sort path."""
    rng = np.random.default_rng(4)
    x, h = random_cloud(rng, 2000, 3, h0=0.16)
    nl = build_neighbours(x, h, RF, 0.0, 3)
    assert mean_neighbours(nl) > 150
    assert_same(nl, brute_force_neighbours(x, h, RF, 0.0, 3))
    assert_well_formed(nl)


def test_line_and_plane_degenerate_extent():
    n = 50
    x = np.zeros((n, 3))
    x[:, 0] = np.arange(n) * 1.0  # exact spacing 1 on the x axis
    h = np.ones(n)
    for dim in (2, 3):
        nl = build_neighbours(x, h, RF, 0.0, dim)
        assert_same(nl, brute_force_neighbours(x, h, RF, 0.0, dim))
        # distance 2 is exactly the radius -> excluded
        np.testing.assert_array_equal(nl.row(10), [9, 11])
        np.testing.assert_array_equal(nl.row(0), [1])
    # line along z, random spacing; plane z = const in 3D
    rng = np.random.default_rng(5)
    x = np.zeros((300, 3))
    x[:, 2] = np.sort(rng.random(300)) * 10.0
    h = np.full(300, 0.05)
    nl = build_neighbours(x, h, RF, 0.01, 3)
    assert_same(nl, brute_force_neighbours(x, h, RF, 0.01, 3))
    assert nl.nnz > 0
    x = rng.random((1000, 3))
    x[:, 2] = 0.5
    nl = build_neighbours(x, np.full(1000, 0.03), RF, 0.0, 3)
    assert_same(nl, brute_force_neighbours(x, np.full(1000, 0.03), RF, 0.0, 3))


def test_2d_ignores_z():
    """dim=2: z is ignored, e.g. particles on a vertical line all coincide."""
    rng = np.random.default_rng(6)
    x, h = random_cloud(rng, 800, 2, h0=0.03)
    x_noisy = x.copy()
    x_noisy[:, 2] = rng.random(800) * 100.0
    nl = build_neighbours(x, h, RF, 0.0, 2)
    nl_noisy = build_neighbours(x_noisy, h, RF, 0.0, 2)
    assert_same(nl_noisy, (nl.offsets, nl.idx))
    assert_same(nl_noisy, brute_force_neighbours(x_noisy, h, RF, 0.0, 2))
    # all at the same (x, y), different z: everybody neighbours everybody
    xz = np.zeros((20, 3))
    xz[:, 2] = np.arange(20.0)
    nl = build_neighbours(xz, np.full(20, 0.1), RF, 0.0, 2)
    assert np.all(np.diff(nl.offsets) == 19)
    nl3 = build_neighbours(xz, np.full(20, 0.1), RF, 0.0, 3)
    assert nl3.nnz == 0


def test_empty_single_and_all_inactive():
    for dim in (2, 3):
        nl = build_neighbours(np.zeros((0, 3)), np.zeros(0), RF, 0.1, dim)
        assert isinstance(nl, NeighbourList)
        np.testing.assert_array_equal(nl.offsets, [0])
        assert nl.idx.shape == (0,) and nl.idx.dtype == np.int32
        assert max_neighbours(nl) == 0 and mean_neighbours(nl) == 0.0
        assert not needs_rebuild(nl, np.zeros((0, 3)), np.zeros(0))
        nl = build_neighbours(np.ones((1, 3)), np.ones(1), RF, 0.1, dim)
        np.testing.assert_array_equal(nl.offsets, [0, 0])
        assert nl.row(0).size == 0
        nl = build_neighbours(np.zeros((5, 3)), np.ones(5), RF, 0.0, dim,
                              active=np.zeros(5, dtype=bool))
        np.testing.assert_array_equal(nl.offsets, np.zeros(6))
        # coincident particles: distance 0 < radius
        nl = build_neighbours(np.zeros((5, 3)), np.ones(5), RF, 0.0, dim)
        np.testing.assert_array_equal(nl.row(2), [0, 1, 3, 4])
    # zero radius: d2 < 0 is never true
    nl = build_neighbours(np.zeros((5, 3)), np.zeros(5), RF, 0.0, 3)
    assert nl.nnz == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_active_mask(dim):
    rng = np.random.default_rng(40 + dim)
    x, h = random_cloud(rng, 2000, dim, h0=0.02 if dim == 2 else 0.05)
    active = (rng.random(2000) < 0.7).astype(np.int8)
    # inactive particles may sit anywhere, even at non-finite positions
    x[np.flatnonzero(active == 0)[:5]] = np.nan
    nl = build_neighbours(x, h, RF, 0.005, dim, active=active)
    assert_same(nl, brute_force_neighbours(x, h, RF, 0.005, dim, active))
    assert_same(nl, kdtree_neighbours(x, h, RF, 0.005, dim, active != 0))
    assert_well_formed(nl)
    inactive = np.flatnonzero(active == 0)
    assert np.all(np.diff(nl.offsets)[inactive] == 0)
    assert not np.isin(nl.idx, inactive).any()
    assert mean_neighbours(nl) == pytest.approx(nl.nnz / active.sum())
    # the bool mask gives the same list
    nl_b = build_neighbours(x, h, RF, 0.005, dim, active=active.astype(bool))
    assert_same(nl_b, (nl.offsets, nl.idx))


def test_sparse_cloud_caps_cells_and_far_clusters():
    """Tiny h in a huge box: the grid is capped at 4 N + 64 cells."""
    rng = np.random.default_rng(7)
    n = 400
    x = rng.random((n, 3)) * 1.0e3
    x[:200] = 1.0e4 + rng.random((200, 3)) * 0.1  # a dense far-away cluster
    h = np.full(n, 1e-3)
    h[:200] = 0.01
    nl = build_neighbours(x, h, RF, 0.0, 3)
    ext = x.max(0) - x.min(0)
    n_cells = np.prod(np.floor(ext / nl.cell_size) + 1)
    assert n_cells <= 4 * n + 64
    assert nl.cell_size > 100 * (RF * h.max())
    assert_same(nl, brute_force_neighbours(x, h, RF, 0.0, 3))
    assert nl.nnz > 0


def test_rebuild_criterion_keeps_all_pairs():
    """Moves with 2 max|dx| + rf max(dh, 0) <= skin: no rebuild needed and
    the old list contains every pair within the current radius (brute force
    with skin 0). Then one particle beyond: rebuild needed."""
    rng = np.random.default_rng(8)
    n, dim = 2500, 3
    x, h = random_cloud(rng, n, dim, h0=0.05, h_ratio=1.5)
    skin = 0.01
    nl = build_neighbours(x, h, RF, skin, dim)
    old_pairs = pair_set(nl.offsets, nl.idx)
    # (a) pure motion, every particle moved by 0.49 skin: 2 * 0.49 < 1
    d = rng.normal(size=(n, 3))
    d *= 0.49 * skin / np.linalg.norm(d, axis=1, keepdims=True)
    assert not needs_rebuild(nl, x + d, h)
    now = pair_set(*brute_force_neighbours(x + d, h, RF, 0.0, dim))
    assert len(now) > 10 * n
    assert now <= old_pairs
    # (b) motion + growth of h: 2 * 0.3 skin + rf * 0.39 skin / rf < skin
    d *= rng.random((n, 1)) * 0.3 / 0.49
    x1 = x + d
    h1 = h + rng.random(n) * (0.39 * skin / RF + 0.1 * skin) - 0.1 * skin
    dmax, dhmax = max_displacement(nl, x1, h1)
    assert dmax == pytest.approx(np.linalg.norm(d, axis=1).max(), rel=1e-12)
    assert dhmax == pytest.approx(max(0.0, (h1 - h).max()), rel=1e-12)
    assert 0.9 * skin < 2 * dmax + RF * dhmax <= skin
    assert not needs_rebuild(nl, x1, h1)
    now = pair_set(*brute_force_neighbours(x1, h1, RF, 0.0, dim))
    assert len(now) > 10 * n
    assert now <= old_pairs
    # update_neighbours keeps the same list
    same = update_neighbours(nl, x1, h1, dim)
    assert same is nl and nl.n_builds == 1
    # beyond the skin: one particle moves by 0.51 skin
    x2 = x1.copy()
    x2[123, 0] = x[123, 0] + 0.51 * skin
    assert needs_rebuild(nl, x2, h1)
    # ... or h grows by more than skin / rf
    h2 = h.copy()
    h2[7] += 1.01 * skin / RF
    assert needs_rebuild(nl, x, h2)
    assert not needs_rebuild(nl, x, h - 0.5 * skin)  # shrinking h is safe
    # NaN positions force a rebuild (and the rebuild then raises)
    x3 = x.copy()
    x3[3, 1] = np.nan
    assert needs_rebuild(nl, x3, h)


def test_a_body_moving_as_a_whole_needs_no_rebuild():
    """Only displacements relative to a common one count: a cloud carried
    by 50 skins (a flying body) keeps its list, whose pairs are then still
    every pair within the radius (brute force); with random moves of up to
    0.3 skin on top, max_displacement gives about 0.3 skin (the common
    displacement taken out: the box's centre, off the moves' own centre by
    their round-off asymmetry) and no rebuild; one particle moved against
    the others changes its pairs' separations by as much, so needs one
    from a skin on (the criterion before, 2 max |d| > skin, from half a
    skin). The centre of the box is not the best common displacement:
    random directions of one length (a box centred near 0) give max |d|
    itself (c = 0 taken when smaller)."""
    rng = np.random.default_rng(12)
    n, dim = 2000, 3
    x, h = random_cloud(rng, n, dim, h0=0.05)
    skin = 0.01
    nl = build_neighbours(x, h, RF, skin, dim)
    old_pairs = pair_set(nl.offsets, nl.idx)
    carry = np.array([50.0 * skin, -20.0 * skin, 7.0 * skin])
    assert max_displacement(nl, x + carry, h)[0] <= 1e-12
    assert not needs_rebuild(nl, x + carry, h)
    d = rng.uniform(-1.0, 1.0, (n, 3))
    d *= 0.3 * skin / np.linalg.norm(d, axis=1, keepdims=True).max()
    x1 = x + carry + d
    dmax = max_displacement(nl, x1, h)[0]
    assert dmax <= 0.35 * skin and not needs_rebuild(nl, x1, h)
    now = pair_set(*brute_force_neighbours(x1, h, RF, 0.0, dim))
    assert len(now) > 5 * n and now <= old_pairs
    nl = update_neighbours(nl, x1, h, dim)
    assert nl.n_builds == 1
    x2 = x + carry
    x2[17] += [0.99 * skin, 0.0, 0.0]  # pairs of 17 change by < skin: none missed
    assert not needs_rebuild(nl, x2, h)
    x2[17] += [0.02 * skin, 0.0, 0.0]
    assert needs_rebuild(nl, x2, h)
    # a sphere of displacements of one length: the box's centre is not 0 but
    # max |d| is the better bound and is the one returned
    u = rng.normal(size=(n, 3))
    u *= 0.4 * skin / np.linalg.norm(u, axis=1, keepdims=True)
    assert max_displacement(nl, x + u, h)[0] == pytest.approx(0.4 * skin, rel=1e-12)


def test_rebuild_criterion_is_needed():
    """A pair just outside radius + skin at build time moves inside the
    radius; the displacement then exceeds skin / 2 and the criterion fires
    (it would be wrong to skip the rebuild here)."""
    skin, h0 = 0.1, 1.0
    r = RF * h0
    e = 1e-3
    x = np.zeros((2, 3))
    x[1, 0] = r + skin + 3 * e
    h = np.full(2, h0)
    nl = build_neighbours(x, h, RF, skin, 3)
    assert nl.nnz == 0
    x1 = x.copy()
    x1[0, 0] += 0.5 * (skin + 4 * e)
    x1[1, 0] -= 0.5 * (skin + 4 * e)
    assert brute_force_neighbours(x1, h, RF, 0.0, 3)[1].size == 2
    assert needs_rebuild(nl, x1, h)
    nl = update_neighbours(nl, x1, h, 3)
    assert nl.n_builds == 2 and nl.nnz == 2
    np.testing.assert_array_equal(nl.x_ref, x1)


def test_update_rebuilds_and_matches_fresh_build():
    rng = np.random.default_rng(9)
    n, dim = 1500, 2
    x, h = random_cloud(rng, n, dim, h0=0.02)
    skin = 0.004
    nl = build_neighbours(x, h, RF, skin, dim)
    x1 = x + rng.normal(scale=skin, size=(n, 3)) * [1, 1, 0]
    nl1 = update_neighbours(nl, x1, h, dim)
    assert nl1 is nl and nl.n_builds == 2
    assert_same(nl, brute_force_neighbours(x1, h, RF, skin, dim))
    np.testing.assert_array_equal(nl.x_ref, x1)
    # a changed active mask forces a rebuild even without motion
    active = np.ones(n, dtype=bool)
    active[::3] = False
    nl = update_neighbours(nl, x1, h, dim, active=active)
    assert nl.n_builds == 3
    assert_same(nl, brute_force_neighbours(x1, h, RF, skin, dim, active))
    nl = update_neighbours(nl, x1, h, dim, active=active)
    assert nl.n_builds == 3
    # displacement of inactive particles does not trigger rebuilds
    x2 = x1.copy()
    x2[::3] += 10.0
    assert not needs_rebuild(nl, x2, h)
    nl = update_neighbours(nl, x2, h, dim, active=None)
    assert nl.n_builds == 4 and nl.active_ref is None
    assert_same(nl, brute_force_neighbours(x2, h, RF, skin, dim))
    # growing h: more pairs, idx storage grows; shrinking back (after a
    # move): the storage is reused, results stay exact
    h_big = 1.5 * h
    nl = update_neighbours(nl, x2, h_big, dim)
    assert nl.n_builds == 5
    assert_same(nl, brute_force_neighbours(x2, h_big, RF, skin, dim))
    buf = nl.idx
    x3 = x2 + np.where(x2[:, :1] > np.median(x2[:, 0]), 1.2 * skin, 0.0) * [1.0, 0.0, 0.0]
    nl = update_neighbours(nl, x3, h, dim)
    assert nl.n_builds == 6 and np.shares_memory(nl.idx, buf)
    assert_same(nl, brute_force_neighbours(x3, h, RF, skin, dim))
    # a failing rebuild (NaN position of an active particle) raises and
    # leaves the list untouched
    before = (nl.offsets.copy(), nl.idx.copy())
    x4 = x3.copy()
    x4[5, 0] = np.nan
    with pytest.raises(ValueError):
        update_neighbours(nl, x4, h, dim)
    assert_same(nl, before)
    assert nl.n_builds == 6
    # arrays replaced from outside (restart from a checkpoint), one of them
    # read-only: the rebuild must not depend on the old storage
    nl.offsets = nl.offsets.copy()
    ro = nl.idx.copy()
    ro.flags.writeable = False
    nl.idx = ro
    x5 = x3 + np.where(x3[:, 1:2] > np.median(x3[:, 1]), 1.2 * skin, 0.0) * [0.0, 1.0, 0.0]
    nl = update_neighbours(nl, x5, h, dim)
    assert nl.n_builds == 7 and not np.shares_memory(nl.idx, ro)
    assert_same(nl, brute_force_neighbours(x5, h, RF, skin, dim))


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2,
                    reason="needs at least 2 Numba threads")
def test_bitwise_identical_for_1_and_2_threads():
    rng = np.random.default_rng(11)
    x, h = random_cloud(rng, 30000, 3, h0=0.02, h_ratio=3.0)
    h[:5] *= 8.0  # exercise the big list too
    n_threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        nl1 = build_neighbours(x, h, RF, 0.002, 3)
        d1 = max_displacement(nl1, x + 1e-3 * np.sin(x), h)
        numba.set_num_threads(2)
        nl2 = build_neighbours(x, h, RF, 0.002, 3)
        d2 = max_displacement(nl2, x + 1e-3 * np.sin(x), h)
    finally:
        numba.set_num_threads(n_threads)
    assert nl1.nnz > 20 * x.shape[0] and nl1.n_big > 0
    assert nl1.offsets.tobytes() == nl2.offsets.tobytes()
    assert nl1.idx.tobytes() == nl2.idx.tobytes()
    assert d1 == d2


def test_input_validation():
    x = np.zeros((4, 3))
    h = np.ones(4)
    with pytest.raises(ValueError):
        build_neighbours(x, h, RF, 0.0, 4)
    with pytest.raises(ValueError):
        build_neighbours(np.zeros((4, 2)), h, RF, 0.0, 2)
    with pytest.raises(ValueError):
        build_neighbours(x, np.ones(3), RF, 0.0, 3)
    with pytest.raises(ValueError):
        build_neighbours(x, h, RF, -1.0, 3)
    with pytest.raises(ValueError):
        build_neighbours(x, h, 0.0, 0.0, 3)
    with pytest.raises(ValueError):
        build_neighbours(x, -h, RF, 0.0, 3)
    x[1, 0] = np.inf
    with pytest.raises(ValueError):
        build_neighbours(x, h, RF, 0.0, 3)
