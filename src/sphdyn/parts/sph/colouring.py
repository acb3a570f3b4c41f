r"""Slab colouring of a neighbour list: each pair's terms formed once and written
to both of its rows, with no two threads writing one row.

The particles are sorted into slabs across the axis of largest extent, each
inner slab at least as thick as the longest listed pair along that axis
(both measured at the same positions, those of the list's build), so a
listed pair joins particles of one slab or of two adjacent ones; the slabs
hold equal shares of the pairs where the body allows (:func:`pair_colouring`).
Their *rank* is their place in the order by slab, then by index. A pair is
worked by the row of lower rank (its *own* pair; :func:`own_pairs_first`
puts them at the head of each row) and written to both rows, so slab ``s``
writes only to rows of ``s`` and ``s + 1``: the even slabs can be worked
concurrently, then the odd ones (two colours). The order in which a row's
terms are summed is fixed by the colouring, not by the number of threads.

This is the half-list form of a pair loop (as with LAMMPS's ``newton on``)
with the race-free scheduling of a domain colouring. It needs each pair's
data to be the same in both of its rows (the pair factors of
:func:`~sphdyn.parts.sph.gradient.velocity_gradient` are: they depend on
:math:`r_{ij}^2` and :math:`h_i + h_j` only; couplings take pairs out in both
rows) and the list to be symmetric (the Verlet list is).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

#: Upper limit of the number of slabs (thicker slabs beyond it: a particle far
#: from the others must not make the arrays huge; thicker slabs stay valid).
MAX_SLABS = 4096


class PairColouring(NamedTuple):
    """The slabs of :func:`pair_colouring`.

    rank : (N,) int32, each particle's place in the order by slab, then index.
    order : (N,) int32, the particles in that order.
    start : (S + 1,) int64, slab ``s`` is ``order[start[s]:start[s + 1]]``.
    """

    rank: np.ndarray
    order: np.ndarray
    start: np.ndarray


@njit(cache=True, error_model="numpy", parallel=True)
def longest_pair(y, offsets, idx):
    """Largest ``|y_i - y_j|`` over the listed pairs (``y`` (N,) one coordinate
    [m]; ``offsets``, ``idx`` the CSR list); 0 without pairs."""
    n = y.shape[0]
    best = np.zeros(n)
    for i in prange(n):
        b = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            d = abs(y[i] - y[idx[k]])
            if d > b:
                b = d
        best[i] = b
    return best.max() if n else 0.0


class ListColouring(NamedTuple):
    """What the gradient and force passes take of a list's colouring
    (:func:`colour_pairs`; the ranks are needed only to order the rows).

    order, start : as in :class:`PairColouring`.
    n_own : (N,) int32, the own pairs at the head of each row.
    """

    order: np.ndarray
    start: np.ndarray
    n_own: np.ndarray


def colour_pairs(x: np.ndarray, offsets: np.ndarray, idx: np.ndarray,
                 active: np.ndarray | None = None) -> ListColouring:
    """The list's slabs (:func:`pair_colouring`) and its own pairs put at the
    head of each row (:func:`own_pairs_first`, ``idx`` reordered in place)."""
    col = pair_colouring(x, offsets, idx, active)
    return ListColouring(col.order, col.start, own_pairs_first(col.rank, offsets, idx))


def pair_colouring(x: np.ndarray, offsets: np.ndarray, idx: np.ndarray,
                   active: np.ndarray | None = None) -> PairColouring:
    """Slabs of the list ``offsets, idx`` at positions ``x`` (N, 3) [m].

    The axis is the one of largest extent of the ``active`` particles (all if
    None; the others have empty rows and go to the nearest slab). Each slab
    but the first and the last is at least ``w`` thick, ``w`` the longest
    listed pair along the axis at ``x`` (times 1 + 1e-9, so that rounding
    cannot put a pair of exactly that length over three slabs).

    The slabs hold equal shares of the listed pairs (:func:`balanced_bounds`)
    when that allows four or more of them: each colour then has an even
    number of slabs of equal work, which the static split of a parallel
    loop gives to two threads in equal halves (the paper's disc, 13 slabs of
    equal thickness: the threads' loads 31 and 21 % of the pass in one colour,
    BENCHMARKS.md 2026-11-28 later). Otherwise (a compact body, a particle
    far from the others) ``floor(extent / w)`` slabs of equal thickness, at
    least ``extent / MAX_SLABS`` thick, the last one taking the rest. Neither
    depends on the number of threads, so neither do the results.
    """
    n = x.shape[0]
    sel = x if active is None else x[active]
    if sel.shape[0] == 0:
        return PairColouring(np.arange(n, dtype=np.int32), np.arange(n, dtype=np.int32),
                             np.array([0, n], dtype=np.int64))
    lo, hi = sel.min(axis=0), sel.max(axis=0)
    axis = int(np.argmax(hi - lo))
    y = np.ascontiguousarray(x[:, axis])
    longest = longest_pair(y, offsets, idx) * (1.0 + 1e-9)
    bounds = balanced_bounds(y, np.diff(offsets), longest)
    if bounds is not None:
        slab = np.searchsorted(bounds, y, side="right").astype(np.int64)
        slabs = bounds.shape[0] + 1
    else:
        extent = float(hi[axis] - lo[axis])
        width = max(longest, extent / MAX_SLABS)
        slabs = max(1, int(extent / width)) if width > 0.0 else 1
        slab = np.zeros(n, dtype=np.int64)
        if slabs > 1:
            slab = np.clip(np.floor((y - lo[axis]) / width), 0, slabs - 1).astype(np.int64)
    order = np.argsort(slab, kind="stable").astype(np.int32)
    rank = np.empty(n, dtype=np.int32)
    rank[order] = np.arange(n, dtype=np.int32)
    start = np.zeros(slabs + 1, dtype=np.int64)
    start[1:] = np.cumsum(np.bincount(slab, minlength=slabs))
    return PairColouring(rank, order, start)


def balanced_bounds(y: np.ndarray, weight: np.ndarray, width: float) -> np.ndarray | None:
    """Inner slab bounds (S - 1,) [m] along ``y`` (N,) that give each of ``S``
    slabs an equal share of ``weight`` (N,) (the listed pairs of each row),
    every inner slab at least ``width`` [m] thick: the largest ``S``, a
    multiple of 4 and at most ``MAX_SLABS``, for which the quantiles of the
    weight are that far apart; None if not even ``S = 4`` is. Slab ``s`` is
    ``bounds[s - 1] <= y < bounds[s]``. A pair shorter than ``width`` cannot
    skip a slab: from ``y_i < bounds[s]`` to ``y_j >= bounds[s + 1]`` is
    farther than ``width``."""
    has = weight > 0
    if width <= 0.0 or not has.any():
        return None
    ys = y[has]
    order = np.argsort(ys, kind="stable")
    ys = ys[order]
    cw = np.cumsum(weight[has][order])
    cap = min(int((ys[-1] - ys[0]) / width), MAX_SLABS)
    for slabs in range(cap - cap % 4, 3, -4):
        b = ys[np.searchsorted(cw, cw[-1] * np.arange(1, slabs) / slabs)]
        if np.all(np.diff(b) >= width):
            return b
    return None


@njit(cache=True, error_model="numpy", parallel=True)
def own_pairs_first(rank, offsets, idx):
    """Put each row's own pairs (``rank[j] > rank[i]``, the pairs the force
    pass works from row ``i``) first, in the order they had, the others after
    them, in place (the list keeps its pairs); returns ``n_own`` (N,) int32,
    the own pairs of each row. :func:`~sphdyn.parts.sph.gradient.velocity_gradient`
    keeps the two parts apart when it partitions the rows, so the force pass
    visits its pairs without testing the ranks."""
    n = rank.shape[0]
    n_own = np.zeros(n, dtype=np.int32)
    width = 0
    for i in range(n):
        width = max(width, offsets[i + 1] - offsets[i])
    chunks = 64
    rest = np.empty((chunks, width), dtype=idx.dtype)
    for t in prange(chunks):
        for i in range(t * n // chunks, (t + 1) * n // chunks):
            head = offsets[i]
            u = 0
            for k in range(offsets[i], offsets[i + 1]):
                j = idx[k]
                if rank[j] > rank[i]:
                    idx[head] = j
                    head += 1
                else:
                    rest[t, u] = j
                    u += 1
            for q in range(u):
                idx[head + q] = rest[t, q]
            n_own[i] = head - offsets[i]
    return n_own
