"""Candidate loops of one row: count (pass 1) and collect (pass 2).

Particle ``i`` scans the cells of its stencil (:func:`.grid._stencil`) in
the fine grid and then in the coarse grid (the large-h particles; empty when
there is one grid), with the pair test of the package docstring. A grid is
the tuple of :func:`.grid._make_grid`, unpacked. ``_count_cells`` only
counts (branch-free loop); ``_collect_cells`` writes the hits, found 64
candidates at a time through a bit mask and count-trailing-zeros
(``_cttz``).
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from .grid import _stencil


@njit(cache=True, error_model="numpy")
def _count_cells(i, x, h, dim, half_rf, skin, lo, inv_cs, nc, r_grid, h_top,
                 cell_start, order, xs, ys, zs, hs):
    """Candidates of a grid (:func:`.grid._make_grid`'s tuple, unpacked)
    within the pair radius of ``i`` (``i`` itself included if it is in the
    grid); branch-free, vectorised loop."""
    xi0 = x[i, 0]
    xi1 = x[i, 1]
    xi2 = x[i, 2]
    hi = h[i]
    nx, ny = nc[0], nc[1]
    x0, x1, y0, y1, z0, z1 = _stencil(i, x, h, dim, half_rf, skin, r_grid,
                                      lo, inv_cs, nc, h_top)
    n = 0
    for zc in range(z0, z1 + 1):
        for yc in range(y0, y1 + 1):
            base = nx * (yc + ny * zc)
            s0 = cell_start[base + x0]
            s1 = cell_start[base + x1 + 1]
            if dim == 3:
                for s in range(s0, s1):
                    d0 = xi0 - xs[s]
                    d1 = xi1 - ys[s]
                    d2 = xi2 - zs[s]
                    r = half_rf * (hi + hs[s]) + skin
                    n += d0 * d0 + d1 * d1 + d2 * d2 < r * r
            else:
                for s in range(s0, s1):
                    d0 = xi0 - xs[s]
                    d1 = xi1 - ys[s]
                    r = half_rf * (hi + hs[s]) + skin
                    n += d0 * d0 + d1 * d1 < r * r
    return n


@intrinsic
def _cttz(typingctx, v):
    """Number of trailing zero bits of a nonzero uint64 (LLVM ``cttz``)."""
    sig = types.uint64(types.uint64)

    def codegen(context, builder, signature, args):
        return builder.cttz(args[0], ir.Constant(ir.IntType(1), 1))

    return sig, codegen


@njit(cache=True, error_model="numpy")
def _collect_cells(i, n, buf, x, h, dim, half_rf, skin, lo, inv_cs, nc,
                   r_grid, h_top, cell_start, order, xs, ys, zs, hs):
    """Append the neighbours of ``i`` in a grid (:func:`.grid._make_grid`'s
    tuple, unpacked) to ``buf[n:]``; return the new count (entries beyond
    ``buf.shape[0]`` counted, not written).

    Candidates are tested in blocks of 64: a branch-free (vectorisable) loop
    sets bit ``k`` of a 64-bit mask for a hit at ``s = b0 + k``, then only
    the set bits are visited (count-trailing-zeros), so the scalar part costs
    O(hits) instead of O(candidates). ``i`` itself is skipped.
    """
    xi0 = x[i, 0]
    xi1 = x[i, 1]
    xi2 = x[i, 2]
    hi = h[i]
    nx, ny = nc[0], nc[1]
    x0, x1, y0, y1, z0, z1 = _stencil(i, x, h, dim, half_rf, skin, r_grid,
                                      lo, inv_cs, nc, h_top)
    nbuf = buf.shape[0]
    one = np.uint64(1)
    for zc in range(z0, z1 + 1):
        for yc in range(y0, y1 + 1):
            base = nx * (yc + ny * zc)
            s0 = cell_start[base + x0]
            s1 = cell_start[base + x1 + 1]
            for b0 in range(s0, s1, 64):
                b1 = min(b0 + 64, s1)
                m = np.uint64(0)
                if dim == 3:
                    for s in range(b0, b1):
                        d0 = xi0 - xs[s]
                        d1 = xi1 - ys[s]
                        d2 = xi2 - zs[s]
                        r = half_rf * (hi + hs[s]) + skin
                        hit = d0 * d0 + d1 * d1 + d2 * d2 < r * r
                        m |= np.uint64(hit) << np.uint64(s - b0)
                else:
                    for s in range(b0, b1):
                        d0 = xi0 - xs[s]
                        d1 = xi1 - ys[s]
                        r = half_rf * (hi + hs[s]) + skin
                        hit = d0 * d0 + d1 * d1 < r * r
                        m |= np.uint64(hit) << np.uint64(s - b0)
                while m != 0:
                    j = order[b0 + np.int64(_cttz(m))]
                    if j != i:
                        if n < nbuf:
                            buf[n] = j
                        n += 1
                    m &= m - one
    return n
