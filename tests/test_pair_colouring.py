"""The slab colouring of the force pass (each pair once, written to both rows).

The slabs must put every listed pair in one slab or two adjacent ones (else
two threads could write one row), and the pass over them must give what a
gather over both rows gives: checked against a NumPy gather written out from
:func:`sphdyn.parts.sph.passes.forces`' formula, with per-particle viscosity
coefficients, zero-mass particles, pairs taken out by a coupling and the
signal speed on. Tolerance: the two differ in the order of their sums only,
1e-13 of the largest term.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from sphdyn import kernels
from sphdyn.neighbours import build_neighbours
from sphdyn.parts.sph.colouring import (MAX_SLABS, balanced_bounds, colour_pairs,
                                        own_pairs_first, pair_colouring)
from sphdyn.parts.sph.passes import forces
from sphdyn.parts.sph.gradient import gradient_scratch, velocity_gradient


def _cloud(dim, shape, dx=0.01, seed=0):
    """A jittered lattice of ``shape`` particles with varied h, masses,
    densities, wave speeds, velocities and stress terms, and its list with a
    skin."""
    rng = np.random.default_rng(seed)
    axes = [np.arange(k) * dx for k in shape] + [np.zeros(1)] * (3 - len(shape))
    x = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    n = x.shape[0]
    x[:, :dim] += 0.2 * dx * rng.uniform(-1, 1, (n, dim))
    h = 1.3 * dx * rng.uniform(0.9, 1.1, n)
    kid = kernels.kernel_id("cubic_spline")
    q = kernels.support(kid)
    nl = build_neighbours(x, h, q, 0.3 * q * h.max(), dim)
    rho = rng.uniform(2000.0, 2600.0, n)
    m = rho * dx**dim
    v = rng.normal(scale=5.0, size=(n, 3))
    if dim == 2:
        v[:, 2] = 0.0
    col = colour_pairs(x, nl.offsets, nl.idx)
    F = np.zeros(nl.idx.size, np.float32)
    count = np.zeros(n, np.int32)
    velocity_gradient(x, v, h, m, rho, nl.offsets, nl.idx, col.n_own, kid,
                      kernels.normalisation(kid, dim), dim, 1.0, False, F,
                      np.zeros((n, 3, 3)), np.zeros((n, 3, 3)), count,
                      gradient_scratch(nl.offsets))
    P = rng.normal(scale=1.0, size=(n, 3, 3))  # sigma B / rho^2 [Pa m^6/kg^2]
    return dict(x=x, v=v, m=m, rho=rho, h=h, c=rng.uniform(2000.0, 4000.0, n), P=P,
                F=F, count=count, nl=nl, dim=dim, col=col)


def _gather(c, alpha, beta, support_scale=1.0):
    """``a``, ``dedt_av``, ``signal`` by a gather over both rows, written out
    from the formula of :func:`forces` (pairs with ``F = 0`` or a zero-mass
    neighbour contribute nothing; in 2D no z component)."""
    x, v, m, rho, h, cs, P, F = (c[k] for k in ("x", "v", "m", "rho", "h", "c", "P", "F"))
    nl = c["nl"]
    n = x.shape[0]
    a, heat, sig = np.zeros((n, 3)), np.zeros(n), np.zeros(n)
    for i in range(n):
        for k in range(nl.offsets[i], nl.offsets[i + 1]):  # whole rows (skin: F = 0)
            j = nl.idx[k]
            if F[k] == 0.0 or m[j] == 0.0:
                continue
            d = x[i] - x[j]
            w = v[i] - v[j]
            g = float(F[k]) * d
            f = (P[i] + P[j]) @ g
            if c["dim"] == 2:
                f[2] = 0.0  # the plane's components only
            if w @ d < 0.0:
                hij = support_scale * 0.5 * (h[i] + h[j])
                mu = hij * (w @ d) / (d @ d + 0.01 * hij**2)
                aij = 0.5 * (alpha[i] + alpha[j]) * 0.5 * (cs[i] + cs[j])
                bij = 0.5 * (beta[i] + beta[j])
                pi = (-aij * mu + bij * mu * mu) / (0.5 * (rho[i] + rho[j]))
                f = f - pi * g
                heat[i] += 0.5 * m[j] * pi * (w @ g)
                sig[i] = max(sig[i], aij - bij * mu)
            a[i] += m[j] * f
    return a, heat, sig


def _run(c, alpha, beta, signal=True):
    """The pass on the cloud, its outputs filled with NaN first (it must write
    every row); ``signal=False``: the signal speed not wanted."""
    n = c["x"].shape[0]
    nl = c["nl"]
    a, heat = np.full((n, 3), np.nan), np.full(n, np.nan)
    sig = np.full(n if signal else 0, np.nan)
    forces(c["x"], c["v"], c["m"], c["rho"], c["h"], c["c"], c["P"], c["F"], nl.offsets,
           c["count"], nl.idx, c["col"].order, c["col"].start, c["dim"], 1.0, alpha, beta, a,
           heat, sig)
    return a, heat, sig


@pytest.mark.parametrize("dim,shape", [(3, (24, 6, 5)), (2, (9, 30)), (3, (4, 4, 3))],
                         ids=["3d-slabs", "2d-slabs", "3d-one-slab"])
def test_slabs_hold_every_listed_pair_in_adjacent_slabs(dim, shape):
    c = _cloud(dim, shape)
    nl = c["nl"]
    rank, order, start = pair_colouring(c["x"], nl.offsets, nl.idx)
    n = c["x"].shape[0]
    assert np.array_equal(np.sort(order), np.arange(n))
    assert np.array_equal(rank[order], np.arange(n))
    assert start[0] == 0 and start[-1] == n and np.all(np.diff(start) >= 0)
    slab = np.repeat(np.arange(start.size - 1), np.diff(start))[rank]
    rows = np.repeat(np.arange(n), np.diff(nl.offsets))
    assert np.abs(slab[rows] - slab[nl.idx]).max() <= 1
    # within a slab the order is by index (the rank's tie-break)
    for s in range(start.size - 1):
        assert np.all(np.diff(order[start[s]:start[s + 1]]) > 0)
    if shape == (4, 4, 3):
        assert start.size == 2  # thinner than two pairs: one slab
    else:
        assert start.size - 1 >= 4  # enough slabs for two threads per colour


@pytest.mark.parametrize("dim,shape", [(3, (24, 6, 5)), (2, (9, 30)), (3, (4, 4, 3))],
                         ids=["3d-slabs", "2d-slabs", "3d-one-slab"])
def test_each_pair_once_equals_the_gather_over_both_rows(dim, shape):
    c = _cloud(dim, shape, seed=1)
    n = c["x"].shape[0]
    rng = np.random.default_rng(2)
    # zero-mass particles (an initial crack): they get accelerations, give none
    c["m"][rng.choice(n, 6, replace=False)] = 0.0
    # a coupling's pairs taken out in both rows
    nl = c["nl"]
    out = set(rng.choice(n, 8, replace=False).tolist())
    for i in out:
        for k in range(nl.offsets[i], nl.offsets[i + 1]):
            if nl.idx[k] in out:
                c["F"][k] = 0.0
    alpha = rng.uniform(0.5, 1.5, n)
    beta = rng.uniform(1.0, 3.0, n)
    a, heat, sig = _run(c, alpha, beta)
    a_ref, heat_ref, sig_ref = _gather(c, alpha, beta)
    assert np.abs(a - a_ref).max() <= 1e-13 * np.abs(a_ref).max()
    assert np.abs(heat - heat_ref).max() <= 1e-13 * np.abs(heat_ref).max()
    assert np.array_equal(sig, sig_ref)  # a max, no sum: the same value
    assert heat_ref.max() > 0.0 and sig_ref.max() > 0.0  # viscosity was on
    # linear momentum: the pair terms cancel (massive particles)
    ma = (c["m"][:, None] * a).sum(axis=0)
    assert np.abs(ma).max() <= 1e-13 * (c["m"][:, None] * np.abs(a)).sum()
    # one value for all (no pair means), the signal not wanted
    a1, heat1, _ = _run(c, alpha[:1], beta[:1], signal=False)
    a1_ref, heat1_ref, _ = _gather(c, np.full(n, alpha[0]), np.full(n, beta[0]))
    assert np.abs(a1 - a1_ref).max() <= 1e-13 * np.abs(a1_ref).max()
    assert np.abs(heat1 - heat1_ref).max() <= 1e-13 * np.abs(heat1_ref).max()


def test_results_do_not_depend_on_the_thread_count():
    # The order of every row's sum is the colouring's: 1 and 2 threads give
    # the same bits.
    c = _cloud(3, (20, 6, 6), seed=3)
    n = c["x"].shape[0]
    alpha, beta = np.ones(n), np.full(n, 2.0)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = _run(c, alpha, beta)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = _run(c, alpha, beta)
    finally:
        numba.set_num_threads(before)
    for p, q in zip(one, two):
        assert np.array_equal(p, q)


def test_a_far_particle_makes_thicker_slabs_not_huge_arrays():
    # A removed particle left far away (no pairs) must not make millions of
    # slabs: at most MAX_SLABS, and the pairs still in adjacent slabs.
    c = _cloud(3, (10, 5, 5))
    nl = c["nl"]
    x = c["x"].copy()
    x[0] = [1.0e4, 0.0, 0.0]
    offsets = nl.offsets.copy()
    rows = [nl.idx[offsets[i]:offsets[i + 1]] for i in range(x.shape[0])]
    rows = [np.array([], np.int32)] + [r[r != 0] for r in rows[1:]]
    offsets = np.concatenate([[0], np.cumsum([r.size for r in rows])]).astype(np.int64)
    idx = np.concatenate(rows).astype(np.int32)
    rank, order, start = pair_colouring(x, offsets, idx)
    assert 1 <= start.size - 1 <= MAX_SLABS
    slab = np.repeat(np.arange(start.size - 1), np.diff(start))[rank]
    pair_rows = np.repeat(np.arange(x.shape[0]), np.diff(offsets))
    assert np.abs(slab[pair_rows] - slab[idx]).max() <= 1
    # inactive (not in the extent): the slabs are the cloud's
    active = np.ones(x.shape[0], bool)
    active[0] = False
    _, _, start_active = pair_colouring(x, offsets, idx, active)
    assert start_active.size - 1 >= 2


def test_balanced_bounds_split_the_weight_evenly_or_give_up():
    # 100 points of weight 1 at y = 0..99: quantile bounds, the largest
    # multiple of 4 slabs whose inner slabs are at least `width` thick.
    y = np.arange(100.0)
    w = np.ones(100, np.int64)
    assert np.array_equal(balanced_bounds(y, w, 20.0), [24.0, 49.0, 74.0])  # 4 slabs of 25
    b = balanced_bounds(y, w, 10.0)  # 9 slabs of 10 fit: 8 of 12.5
    assert b.size == 7 and np.diff(b).min() >= 10.0
    counts = np.bincount(np.searchsorted(b, y, side="right"))
    assert counts.size == 8 and counts.min() == 12 and counts.max() == 13
    assert balanced_bounds(y, w, 30.0) is None  # 3 slabs at most: not 4
    # points without weight (no pairs) do not count, wherever they are
    y2 = np.concatenate([y, [1.0e4]])
    assert np.array_equal(balanced_bounds(y2, np.append(w, 0), 20.0), [24.0, 49.0, 74.0])


def test_slabs_share_the_pairs_evenly_where_the_body_allows():
    # A cylinder lying along x (a disc's cross-section in y-z): slabs of
    # equal thickness hold few pairs at the ends, many in the middle, which
    # a static two-thread split of each colour shares unevenly. The slabs
    # hold equal shares instead (within two rows' weight: the bounds fall on
    # particles), a multiple of 4 of them, each pair still in one slab or two
    # adjacent ones.
    rng = np.random.default_rng(5)
    g = np.arange(-20, 21) * 0.01
    x = np.stack(np.meshgrid(g, g[:4], g, indexing="ij"), -1).reshape(-1, 3)
    x = x[x[:, 0] ** 2 + x[:, 2] ** 2 <= 0.2 ** 2]
    x += 0.002 * rng.uniform(-1, 1, x.shape)
    h = np.full(x.shape[0], 0.012)
    nl = build_neighbours(x, h, kernels.support(0), 0.1 * 0.024, 3)
    rank, order, start = pair_colouring(x, nl.offsets, nl.idx)
    slabs = start.size - 1
    assert slabs >= 8 and slabs % 4 == 0
    slab = np.repeat(np.arange(slabs), np.diff(start))[rank]
    rows = np.repeat(np.arange(x.shape[0]), np.diff(nl.offsets))
    assert np.abs(slab[rows] - slab[nl.idx]).max() <= 1
    weight = np.bincount(slab[rows], minlength=slabs)
    assert np.abs(weight - weight.mean()).max() <= 2 * np.diff(nl.offsets).max()
    # slabs of equal thickness (as many as fit) would not: the end ones hold
    # under 2/3 of the mean
    y = x[:, 0] - x[:, 0].min()
    longest = np.abs(x[rows, 0] - x[nl.idx, 0]).max()
    thin = int(y.max() / longest)
    uniform = np.bincount(np.minimum((y / (y.max() / thin)).astype(int), thin - 1)[rows])
    assert uniform[0] < (2 / 3) * uniform.mean() and uniform[-1] < (2 / 3) * uniform.mean()
    assert np.abs(weight - weight.mean()).max() < 0.1 * weight.mean()


def test_own_pairs_first_puts_each_pair_in_one_row_head():
    # Each row's first n_own pairs are those of higher rank (the pairs the
    # force pass works from this row), in the order they had, the others
    # after them in theirs; every pair of the symmetric list is own in
    # exactly one of its two rows.
    c = _cloud(3, (12, 5, 4), seed=6)
    nl = c["nl"]
    rng = np.random.default_rng(1)
    for i in range(c["x"].shape[0]):  # rows out of order
        row = nl.idx[nl.offsets[i]:nl.offsets[i + 1]]
        row[:] = rng.permutation(row)
    before = nl.idx.copy()
    rank = pair_colouring(c["x"], nl.offsets, nl.idx).rank
    n_own = own_pairs_first(rank, nl.offsets, nl.idx)
    for i in range(c["x"].shape[0]):
        old = before[nl.offsets[i]:nl.offsets[i + 1]]
        new = nl.idx[nl.offsets[i]:nl.offsets[i + 1]]
        assert list(new[:n_own[i]]) == [j for j in old if rank[j] > rank[i]]
        assert list(new[n_own[i]:]) == [j for j in old if rank[j] < rank[i]]
    assert 2 * n_own.sum() == nl.idx.size
