r"""Slab colouring of a neighbour list: each pair's terms formed once and written
to both of its rows, with no two threads writing one row.

The particles are sorted into slabs across the axis of largest extent, each
slab at least as thick as the longest listed pair along that axis (both
measured at the same positions, those of the list's build), so a listed pair
joins particles of one slab or of two adjacent ones. Their *rank* is their
place in the order by slab, then by index. A pair is worked by the row of
lower rank and written to both rows, so slab ``s`` writes only to rows of
``s`` and ``s + 1``: the even slabs can be worked concurrently, then the odd
ones (two colours). The order in which a row's terms are summed is fixed by
the colouring, not by the number of threads.

This is the half-list form of a pair loop (as with LAMMPS's ``newton on``)
with the race-free scheduling of a domain colouring. It needs each pair's
data to be the same in both of its rows (the pair factors of
:func:`~sphdyn.parts.sph.passes.velocity_gradient` are: they depend on
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


def pair_colouring(x: np.ndarray, offsets: np.ndarray, idx: np.ndarray,
                   active: np.ndarray | None = None) -> PairColouring:
    """Slabs of the list ``offsets, idx`` at positions ``x`` (N, 3) [m].

    The axis is the one of largest extent of the ``active`` particles (all if
    None; the others have empty rows and go to the nearest slab). Slab
    thickness ``w`` = the longest listed pair along the axis at ``x`` (times
    1 + 1e-9, so that rounding of ``(y - lo) / w`` cannot split a pair of
    exactly that length over three slabs), at least ``extent / MAX_SLABS``;
    ``floor(extent / w)`` slabs, the last one taking the rest.
    """
    n = x.shape[0]
    sel = x if active is None else x[active]
    if sel.shape[0] == 0:
        return PairColouring(np.arange(n, dtype=np.int32), np.arange(n, dtype=np.int32),
                             np.array([0, n], dtype=np.int64))
    lo, hi = sel.min(axis=0), sel.max(axis=0)
    axis = int(np.argmax(hi - lo))
    y = np.ascontiguousarray(x[:, axis])
    extent = float(hi[axis] - lo[axis])
    width = max(longest_pair(y, offsets, idx) * (1.0 + 1e-9), extent / MAX_SLABS)
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
