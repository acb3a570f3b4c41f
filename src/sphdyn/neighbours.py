"""Neighbour search: cell-linked list -> Verlet list in CSR form.

Pair criterion
--------------
Two distinct active particles ``i != j`` are neighbours when

.. math::

    |x_i - x_j| < r_{ij}, \\qquad
    r_{ij} = \\text{radius\\_factor} \\cdot 0.5\\,(h_i + h_j) + \\text{skin},

with ``radius_factor = q_max * support_scale`` (kernel support times the
support scale, supplied by the caller) and ``skin >= 0`` the Verlet skin. The
test is evaluated, everywhere in this module (including the brute-force
reference), with the same floating-point expression::

    r  = (radius_factor * 0.5) * (h_i + h_j) + skin
    d2 = dx*dx + dy*dy (+ dz*dz in 3D),   dx = x_i - x_j
    neighbours  <=>  d2 < r*r                      (strict)

so ties are resolved identically by every code path: a pair at *exactly*
the radius (e.g. lattice neighbours with ``d2 == r*r`` in floating point) is
**not** a neighbour. The expression is symmetric bit for bit
(``x_i - x_j == -(x_j - x_i)`` and ``h_i + h_j == h_j + h_i`` exactly), so
the list is exactly symmetric. In 2D (``dim=2``) the z coordinate is ignored.

Output
------
A CSR Verlet list: row ``i`` is ``idx[offsets[i]:offsets[i+1]]`` (int32
particle indices, sorted ascending, never containing ``i``); ``offsets`` is
int64 of length ``N + 1``. Inactive particles have empty rows and appear in
no row. The output depends only on the input arrays, not on the number of
threads (bitwise-reproducible runs and restarts).

Algorithm
---------
1. Bounding box of the active particles (x, y in 2D; x, y, z in 3D).
2. *Large-h split.* With ``h_cut`` the ``(B+1)``-th largest active ``h``
   (``B = _BIG_MAX = 64``), if the largest pair radius ``rf*h_max + skin``
   exceeds ``_BIG_RADIUS_RATIO = 1.5`` times ``rf*h_cut + skin``, the (at
   most ``B``) particles with ``h > h_cut`` are kept out of the grid in a
   separate "big" list; otherwise ``h_cut = h_max`` and the big list is
   empty. This keeps the cells sized by the bulk of the particles when a
   few particles have a much larger ``h`` (a single-grid cell size equal to
   the maximum radius would put ``(h_max/h)^dim`` times more candidates in
   every cell).
3. Uniform grid of cell size ``cs >= (rf*h_cut + skin) * (1 + 1e-6)`` (the
   largest pair radius among grid particles, with a margin covering rounding
   in the cell-index computation). If the grid would have more than
   ``4 * n_grid + 64`` cells (very sparse clouds, far-apart bodies) the cell
   size is enlarged until it does not. Degenerate extents (line, plane,
   single point) give one cell along the flat axes.
4. Counting sort of the grid particles by flat cell index (stable: ascending
   particle index within a cell); positions and ``h`` are copied in cell
   order so that the candidate loop reads contiguous memory, and cells along
   x are contiguous so each (y, z) row of the stencil is one index range.
5. Rows, two passes in ``prange`` over particles visited in cell order
   (cache locality). Particle ``i`` scans the grid cells within ``k_i``
   cells of its own cell (``k_i = 1`` for grid particles,
   ``k_i = ceil(r_i / cs)`` with ``r_i = rf*0.5*(h_i + h_cut) + skin`` for
   big particles), then tests every big particle directly.
   (a) Count: branch-free, vectorised candidate loop -> ``counts``; prefix
   sum -> ``offsets``. (b) Fill: candidates in blocks of 64 give a hit
   bit mask (vectorised), set bits are visited with count-trailing-zeros and
   the hits collected in a per-chunk scratch buffer, then stored sorted into
   ``idx[offsets[i]:offsets[i+1]]`` (rank sort for rows <= 128 entries,
   heap sort above). Every pair is examined from both ends; each row is
   written only by its own iteration (gather form, race free). A row whose
   length differed between the passes (impossible: identical expressions)
   would raise ``RuntimeError`` rather than write out of bounds.

Cost: ``O(N * (3^dim * n_per_cell + n_big))`` per build; memory ``O(N +
n_cells + nnz)``.

Limitations: a single uniform grid. If ``h`` varies smoothly over a large
ratio (so that more than ``B`` particles have a large ``h``) the cell size is
set by the largest ``h`` and small-``h`` regions scan proportionally more
candidates. Clouds whose bounding box is huge compared to the particle
spacing (hit the cell cap) also scan more candidates per cell.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, prange, types
from numba.extending import intrinsic

__all__ = [
    "NeighbourList",
    "build_neighbours",
    "needs_rebuild",
    "update_neighbours",
    "brute_force_neighbours",
    "max_neighbours",
    "mean_neighbours",
    "max_displacement",
]

# Relative enlargement of the cell size over the largest grid pair radius:
# guarantees |c_i - c_j| <= k along each axis despite rounding in
# floor((x - lo) / cs) for up to ~1e9 cells per axis.
_MARGIN = 1e-6
# At most this many large-h particles are kept out of the grid.
_BIG_MAX = 64
# ... and only if it shrinks the grid pair radius by at least this factor.
_BIG_RADIUS_RATIO = 1.5
# Rows up to this length are sorted by rank sort, longer ones by heap sort.
_RANK_SORT_MAX = 128
# Spare capacity of a reallocated idx buffer (rebuilds reuse the storage).
_IDX_HEADROOM = 0.1
# Particles per prange chunk of the fill pass (one scratch buffer per chunk).
_FILL_CHUNK = 1024


class NeighbourList:
    """CSR Verlet list with the state it was built from.

    Attributes
    ----------
    offsets : (N + 1,) int64
        Row pointers; row ``i`` is ``idx[offsets[i]:offsets[i + 1]]``.
    idx : (nnz,) int32
        Neighbour indices, each row sorted ascending, symmetric, no self.
    x_ref : (N, 3) float64
        Copy of the positions at the last build [m].
    h_ref : (N,) float64
        Copy of the smoothing lengths at the last build [m].
    skin : float
        Verlet skin [m].
    radius_factor : float
        ``q_max * support_scale`` [-].
    dim : int
        2 or 3 (dimension used at the build).
    active_ref : (N,) bool or None
        Copy of the active mask used at the build (None = all active).
    n_builds : int
        Number of builds of this list (1 after ``build_neighbours``,
        incremented by every rebuild in ``update_neighbours``).
    cell_size : float
        Grid cell size of the last build [m] (diagnostic).
    n_big : int
        Number of large-h particles kept out of the grid (diagnostic).
    """

    def __init__(self, offsets, idx, x_ref, h_ref, skin, radius_factor, dim,
                 active_ref=None, n_builds=1, cell_size=0.0, n_big=0):
        self.offsets = offsets
        self.idx = idx
        self.x_ref = x_ref
        self.h_ref = h_ref
        self.skin = float(skin)
        self.radius_factor = float(radius_factor)
        self.dim = int(dim)
        self.active_ref = active_ref
        self.n_builds = int(n_builds)
        self.cell_size = float(cell_size)
        self.n_big = int(n_big)

    @property
    def n(self) -> int:
        """Number of particles (rows)."""
        return self.offsets.shape[0] - 1

    @property
    def nnz(self) -> int:
        """Total number of (directed) entries, i.e. twice the pair count."""
        return int(self.offsets[-1])

    def row(self, i: int) -> np.ndarray:
        """Neighbours of particle ``i`` (a view into ``idx``)."""
        return self.idx[self.offsets[i]:self.offsets[i + 1]]

    def __repr__(self) -> str:
        return (f"NeighbourList(n={self.n}, nnz={self.nnz}, dim={self.dim}, "
                f"skin={self.skin:g}, radius_factor={self.radius_factor:g}, "
                f"n_builds={self.n_builds})")


# ---------------------------------------------------------------------------
# Numba kernels
# ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _cell_coord(xa, lo, inv_cs, n):
    """Cell index along one axis, clamped to [0, n - 1]."""
    c = int(math.floor((xa - lo) * inv_cs))
    if c < 0:
        return 0
    if c > n - 1:
        return n - 1
    return c


@njit(cache=True, error_model="numpy")
def _bin_particles(x, h, grid_ids, lo, inv_cs, nc, dim):
    """Counting sort of the grid particles by flat cell index.

    Parameters
    ----------
    x : (N, 3) float64, h : (N,) float64
    grid_ids : (n_grid,) int64
        Particles to bin, ascending.
    lo : (3,) float64
        Lower corner of the grid [m].
    inv_cs : float
        1 / cell size [1/m].
    nc : (3,) int64
        Cells per axis (``nc[2] == 1`` in 2D).
    dim : int

    Returns
    -------
    cell_start : (n_cells + 1,) int64
        Entries of cell ``c`` are ``[cell_start[c], cell_start[c + 1])``;
        flat index ``c = cx + nx * (cy + ny * cz)``.
    order : (n_grid,) int32
        Particle index of every sorted entry (ascending within a cell).
    xs, ys, zs, hs : (n_grid,) float64
        Coordinates and smoothing lengths in sorted order (structure of
        arrays, so that the candidate loops vectorise).
    """
    ng = grid_ids.shape[0]
    nx, ny, nz = nc[0], nc[1], nc[2]
    ncell = nx * ny * nz
    cell = np.empty(ng, dtype=np.int64)
    cell_start = np.zeros(ncell + 1, dtype=np.int64)
    for t in range(ng):
        i = grid_ids[t]
        cx = _cell_coord(x[i, 0], lo[0], inv_cs, nx)
        cy = _cell_coord(x[i, 1], lo[1], inv_cs, ny)
        cz = 0
        if dim == 3:
            cz = _cell_coord(x[i, 2], lo[2], inv_cs, nz)
        c = cx + nx * (cy + ny * cz)
        cell[t] = c
        cell_start[c + 1] += 1
    for c in range(ncell):
        cell_start[c + 1] += cell_start[c]
    fill = cell_start[:-1].copy()
    order = np.empty(ng, dtype=np.int32)
    xs = np.empty(ng)
    ys = np.empty(ng)
    zs = np.empty(ng)
    hs = np.empty(ng)
    for t in range(ng):
        i = grid_ids[t]
        c = cell[t]
        s = fill[c]
        fill[c] = s + 1
        order[s] = i
        xs[s] = x[i, 0]
        ys[s] = x[i, 1]
        zs[s] = x[i, 2]
        hs[s] = h[i]
    return cell_start, order, xs, ys, zs, hs


@njit(cache=True, error_model="numpy")
def _stencil(i, x, h, dim, half_rf, skin, r_grid, lo, inv_cs, nc, h_cut):
    """Cell ranges ``(x0, x1, y0, y1, z0, z1)`` (inclusive) scanned by ``i``.

    ``k = 1`` cell around the own cell when the largest pair radius of ``i``
    with a grid particle, ``rf * 0.5 * (h_i + h_cut) + skin``, is not larger
    than ``r_grid`` (always true for grid particles), else
    ``k = ceil(r_i (1 + 2e-6) / cs)``.
    """
    nx, ny, nz = nc[0], nc[1], nc[2]
    r_i = half_rf * (h[i] + h_cut) + skin
    k = 1
    if r_i > r_grid:
        k = max(1, int(math.ceil(r_i * (1.0 + 2.0 * _MARGIN) * inv_cs)))
    cx = _cell_coord(x[i, 0], lo[0], inv_cs, nx)
    cy = _cell_coord(x[i, 1], lo[1], inv_cs, ny)
    cz = 0
    if dim == 3:
        cz = _cell_coord(x[i, 2], lo[2], inv_cs, nz)
    return (max(cx - k, 0), min(cx + k, nx - 1), max(cy - k, 0),
            min(cy + k, ny - 1), max(cz - k, 0), min(cz + k, nz - 1))


@njit(cache=True, error_model="numpy")
def _count_row(i, s_self, x, h, dim, half_rf, skin, r_grid, lo, inv_cs, nc,
               cell_start, xs, ys, zs, hs, h_cut, big):
    """Number of neighbours of particle ``i``.

    ``s_self`` is the sorted position of ``i`` in the grid (-1 if ``i`` is a
    big particle). The candidate loop is branch-free (it also counts ``i``
    itself, which is subtracted afterwards with the identical test).
    """
    xi0 = x[i, 0]
    xi1 = x[i, 1]
    xi2 = x[i, 2]
    hi = h[i]
    nx, ny = nc[0], nc[1]
    x0, x1, y0, y1, z0, z1 = _stencil(i, x, h, dim, half_rf, skin, r_grid,
                                      lo, inv_cs, nc, h_cut)
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
    if s_self >= 0:
        r = half_rf * (hi + hi) + skin
        n -= 0.0 < r * r
    for b in range(big.shape[0]):
        j = big[b]
        d0 = xi0 - x[j, 0]
        d1 = xi1 - x[j, 1]
        d2 = d0 * d0 + d1 * d1
        if dim == 3:
            dz = xi2 - x[j, 2]
            d2 = d2 + dz * dz
        r = half_rf * (hi + h[j]) + skin
        if d2 < r * r and j != i:
            n += 1
    return n


@intrinsic
def _cttz(typingctx, v):
    """Number of trailing zero bits of a nonzero uint64 (LLVM ``cttz``)."""
    sig = types.uint64(types.uint64)

    def codegen(context, builder, signature, args):
        return builder.cttz(args[0], ir.Constant(ir.IntType(1), 1))

    return sig, codegen


@njit(cache=True, error_model="numpy")
def _collect_row(i, s_self, buf, x, h, dim, half_rf, skin, r_grid, lo,
                 inv_cs, nc, cell_start, order, xs, ys, zs, hs, h_cut, big):
    """Write the neighbours of ``i`` (unsorted) to ``buf``; return how many.

    Entries beyond ``buf.shape[0]`` are counted but not written.

    Candidates are tested in blocks of 64: a branch-free (vectorisable) loop
    sets bit ``k`` of a 64-bit mask for a hit at ``s = b0 + k``, then only
    the set bits are visited (count-trailing-zeros), so the scalar part costs
    O(hits) instead of O(candidates).
    """
    xi0 = x[i, 0]
    xi1 = x[i, 1]
    xi2 = x[i, 2]
    hi = h[i]
    nx, ny = nc[0], nc[1]
    x0, x1, y0, y1, z0, z1 = _stencil(i, x, h, dim, half_rf, skin, r_grid,
                                      lo, inv_cs, nc, h_cut)
    n = 0
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
                    s = b0 + np.int64(_cttz(m))
                    if s != s_self:
                        if n < nbuf:
                            buf[n] = order[s]
                        n += 1
                    m &= m - one
    for b in range(big.shape[0]):
        j = big[b]
        d0 = xi0 - x[j, 0]
        d1 = xi1 - x[j, 1]
        d2 = d0 * d0 + d1 * d1
        if dim == 3:
            dz = xi2 - x[j, 2]
            d2 = d2 + dz * dz
        r = half_rf * (hi + h[j]) + skin
        if d2 < r * r and j != i:
            if n < nbuf:
                buf[n] = j
            n += 1
    return n


@njit(cache=True, error_model="numpy")
def _sift_down(a, lo, root, end):
    """Restore the max-heap property of ``a[lo:lo + end]`` below ``root``."""
    v = a[lo + root]
    while True:
        child = 2 * root + 1
        if child >= end:
            break
        if child + 1 < end and a[lo + child] < a[lo + child + 1]:
            child += 1
        if v >= a[lo + child]:
            break
        a[lo + root] = a[lo + child]
        root = child
    a[lo + root] = v


@njit(cache=True, error_model="numpy")
def _heap_sort(a, lo, hi):
    """Sort ``a[lo:hi]`` ascending in place (heap sort: O(n log n), no
    recursion, no allocation)."""
    n = hi - lo
    for root in range(n // 2 - 1, -1, -1):
        _sift_down(a, lo, root, n)
    for end in range(n - 1, 0, -1):
        t = a[lo]
        a[lo] = a[lo + end]
        a[lo + end] = t
        _sift_down(a, lo, 0, end)


@njit(cache=True, error_model="numpy")
def _sorted_store(buf, n, out, pos):
    """Store the ``n`` distinct values of ``buf`` sorted into ``out[pos:]``.

    Short rows (``n <= 128``): rank sort, ``out[pos + #{m: buf[m] < v}] = v``
    (branch-free, vectorised, O(n^2)); longer rows: copy and heap sort.
    """
    if n <= _RANK_SORT_MAX:
        for k in range(n):
            v = buf[k]
            r = np.int32(0)
            for m in range(n):
                r += np.int32(buf[m] < v)
            out[pos + r] = v
    else:
        for k in range(n):
            out[pos + k] = buf[k]
        _heap_sort(out, pos, pos + n)


@njit(cache=True, error_model="numpy", parallel=True)
def _count_rows(visit, n_grid, counts, x, h, dim, half_rf, skin, r_grid, lo,
                inv_cs, nc, cell_start, order, xs, ys, zs, hs, h_cut, big):
    """Pass 1: ``counts[i + 1]`` = number of neighbours of ``i``.

    ``visit`` lists the grid particles in cell order (``visit[t] ==
    order[t]`` for ``t < n_grid``) followed by the big particles.
    """
    for t in prange(visit.shape[0]):
        i = visit[t]
        s_self = t if t < n_grid else -1
        counts[i + 1] = _count_row(i, s_self, x, h, dim, half_rf, skin,
                                   r_grid, lo, inv_cs, nc, cell_start, xs, ys,
                                   zs, hs, h_cut, big)


@njit(cache=True, error_model="numpy", parallel=True)
def _fill_rows(visit, n_grid, offsets, idx, max_row, x, h, dim, half_rf, skin,
               r_grid, lo, inv_cs, nc, cell_start, order, xs, ys, zs, hs,
               h_cut, big):
    """Pass 2: write every row of ``idx`` sorted ascending.

    ``visit`` is processed in ``_FILL_CHUNK``-sized chunks, each with its own
    scratch buffer of ``max_row + 1`` entries. Returns the number of rows
    whose length differs from pass 1 (must be 0; such rows are truncated,
    never written out of bounds).
    """
    nv = visit.shape[0]
    nchunk = (nv + _FILL_CHUNK - 1) // _FILL_CHUNK
    bad = 0
    for c in prange(nchunk):
        buf = np.empty(max_row + 1, dtype=np.int32)
        for t in range(c * _FILL_CHUNK, min(nv, (c + 1) * _FILL_CHUNK)):
            i = visit[t]
            s_self = t if t < n_grid else -1
            n = _collect_row(i, s_self, buf, x, h, dim, half_rf, skin, r_grid,
                             lo, inv_cs, nc, cell_start, order, xs, ys, zs,
                             hs, h_cut, big)
            cnt = offsets[i + 1] - offsets[i]
            if n != cnt:
                bad += 1
                n = min(n, cnt)
            _sorted_store(buf, n, idx, offsets[i])
    return bad


@njit(cache=True, error_model="numpy", parallel=True)
def _max_disp_dh(x, x_ref, h, h_ref, active, use_active, dim):
    """Max squared displacement and max increase of h over active particles.

    Returns ``(max_i |x_i - x_ref_i|^2, max(0, max_i (h_i - h_ref_i)))``;
    NaN contributions become +inf. ``max`` is exact and associative, so the
    result does not depend on the thread count or the reduction order.
    """
    n = x.shape[0]
    md2 = 0.0
    mdh = 0.0
    for i in prange(n):
        d2 = 0.0
        dh = 0.0
        if (not use_active) or active[i]:
            d0 = x[i, 0] - x_ref[i, 0]
            d1 = x[i, 1] - x_ref[i, 1]
            d2 = d0 * d0 + d1 * d1
            if dim == 3:
                dz = x[i, 2] - x_ref[i, 2]
                d2 = d2 + dz * dz
            if d2 != d2:
                d2 = np.inf
            dh = h[i] - h_ref[i]
            if dh != dh:
                dh = np.inf
        md2 = max(md2, d2)
        mdh = max(mdh, dh)
    return md2, mdh


@njit(cache=True, error_model="numpy")
def _mask_changed(active, active_ref):
    """True if ``active != 0`` differs from the bool mask ``active_ref``."""
    for i in range(active.shape[0]):
        if (active[i] != 0) != active_ref[i]:
            return True
    return False


_NO_MASK = np.empty(0, dtype=np.bool_)


# ---------------------------------------------------------------------------
# Python drivers
# ---------------------------------------------------------------------------

def _check_inputs(x, h, radius_factor, skin, dim, active):
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    x = np.ascontiguousarray(x, dtype=np.float64)
    h = np.ascontiguousarray(h, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must have shape (N, 3), got {x.shape}")
    n = x.shape[0]
    if h.shape != (n,):
        raise ValueError(f"h must have shape ({n},), got {h.shape}")
    if n >= 2**31 - 1:
        raise ValueError("too many particles for int32 neighbour indices")
    if not (np.isfinite(radius_factor) and radius_factor > 0.0):
        raise ValueError(f"radius_factor must be > 0, got {radius_factor}")
    if not (np.isfinite(skin) and skin >= 0.0):
        raise ValueError(f"skin must be >= 0, got {skin}")
    if active is None:
        act = None
    else:
        act = np.asarray(active)
        if act.shape != (n,):
            raise ValueError(f"active must have shape ({n},), got {act.shape}")
        act = np.ascontiguousarray(act != 0)
    return x, h, act


def _grid_setup(xa, ha, rf, skin, dim):
    """Cell size, grid origin, cells per axis, h_cut and the big mask.

    ``xa`` (n_act, 3), ``ha`` (n_act,) are the active particles.
    """
    n_act = ha.shape[0]
    half_rf = rf * 0.5
    h_max = float(ha.max())
    h_cut = h_max
    big_mask = None
    if n_act > _BIG_MAX + 1:
        kth = n_act - _BIG_MAX - 1
        hc = float(np.partition(ha, kth)[kth])
        if rf * h_max + skin > _BIG_RADIUS_RATIO * (rf * hc + skin):
            h_cut = hc
            big_mask = ha > hc
    n_grid = n_act if big_mask is None else n_act - int(big_mask.sum())
    # Largest pair radius among grid particles, same expression as the test.
    r_grid = half_rf * (h_cut + h_cut) + skin
    lo = np.zeros(3)
    ext = np.zeros(3)
    for a in range(dim):  # per column: NumPy's axis-0 reduction of the
        col = xa[:, a]    # strided (n, dim) view is 20x slower
        lo[a] = col.min()
        ext[a] = col.max() - lo[a]
    cs = r_grid * (1.0 + _MARGIN)
    if not cs > 0.0:  # all h == 0 and skin == 0 among grid particles
        cs = float(ext.max()) if ext.max() > 0.0 else 1.0
    cap = 4.0 * n_grid + 64.0
    while True:
        ncf = [math.floor(ext[a] / cs) + 1.0 if a < dim else 1.0
               for a in range(3)]
        prod = ncf[0] * ncf[1] * ncf[2]
        if prod <= cap:
            break
        cs *= max(1.1, (prod / cap) ** (1.0 / dim))
    nc = np.array([int(v) for v in ncf], dtype=np.int64)
    return cs, lo, nc, h_cut, r_grid, big_mask


def _idx_storage(idx):
    """Writable int32 buffer whose leading part is ``idx`` (its base array if
    ``idx`` is a leading view of one, else ``idx`` itself), or None."""
    if not (isinstance(idx, np.ndarray) and idx.dtype == np.int32
            and idx.ndim == 1 and idx.flags.c_contiguous
            and idx.flags.writeable):
        return None
    b = idx.base
    if (isinstance(b, np.ndarray) and b.dtype == np.int32 and b.ndim == 1
            and b.flags.c_contiguous and b.flags.writeable
            and b.ctypes.data == idx.ctypes.data):
        return b
    return idx


def _build_csr(x, h, act, rf, skin, dim, offsets_buf=None, idx_buf=None):
    """Return ``(offsets, idx, idx_buf, cell_size, n_big)`` for validated
    inputs.

    ``offsets_buf`` ((N + 1,) int64) and ``idx_buf`` (int32) are reused if
    given and large enough; ``idx`` is then a leading view of ``idx_buf``.
    A new ``idx_buf`` gets ``_IDX_HEADROOM`` spare capacity when it replaces
    a too small one.
    """
    n = x.shape[0]
    act_ids = (np.arange(n, dtype=np.int64) if act is None
               else np.flatnonzero(act).astype(np.int64))
    n_act = act_ids.shape[0]
    if n_act > 0:  # validate before touching the buffers of the old list
        xa = x[act_ids]
        ha = h[act_ids]
        if not np.all(np.isfinite(xa[:, :dim])):
            raise ValueError("non-finite position of an active particle")
        if not np.all(np.isfinite(ha)) or ha.min() < 0.0:
            raise ValueError("h of active particles must be finite and >= 0")
    if (isinstance(offsets_buf, np.ndarray) and offsets_buf.shape == (n + 1,)
            and offsets_buf.dtype == np.int64 and offsets_buf.flags.writeable
            and offsets_buf.flags.c_contiguous):
        offsets = offsets_buf
        offsets[:] = 0
    else:
        offsets = np.zeros(n + 1, dtype=np.int64)
    if n_act == 0:
        if idx_buf is None:
            idx_buf = np.empty(0, dtype=np.int32)
        return offsets, idx_buf[:0], idx_buf, 0.0, 0
    cs, lo, nc, h_cut, r_grid, big_mask = _grid_setup(xa, ha, rf, skin, dim)
    if big_mask is None:
        grid_ids = act_ids
        big = np.empty(0, dtype=np.int64)
    else:
        grid_ids = act_ids[~big_mask]
        big = act_ids[big_mask]
    cell_start, order, xs, ys, zs, hs = _bin_particles(x, h, grid_ids, lo,
                                                       1.0 / cs, nc, dim)
    n_grid = order.shape[0]
    visit = np.concatenate((order.astype(np.int64), big))
    args = (x, h, dim, rf * 0.5, skin, r_grid, lo, 1.0 / cs, nc, cell_start,
            order, xs, ys, zs, hs, h_cut, big)
    _count_rows(visit, n_grid, offsets, *args)
    max_row = int(offsets.max())
    np.cumsum(offsets, out=offsets)
    nnz = int(offsets[-1])
    if idx_buf is None:
        idx_buf = np.empty(nnz, dtype=np.int32)
    elif idx_buf.shape[0] < nnz:
        idx_buf = np.empty(int(nnz * (1.0 + _IDX_HEADROOM)), dtype=np.int32)
    idx = idx_buf[:nnz]
    bad = _fill_rows(visit, n_grid, offsets, idx, max_row, *args)
    if bad:
        raise RuntimeError(f"neighbour search: {bad} rows changed length "
                           "between count and fill passes")
    return offsets, idx, idx_buf, cs, big.shape[0]


def build_neighbours(x, h, radius_factor, skin, dim, active=None):
    """Build the Verlet list of all pairs within the h-dependent radius.

    Parameters
    ----------
    x : (N, 3) float64
        Positions [m] (z ignored when ``dim == 2``).
    h : (N,) float64
        Smoothing lengths [m], finite and >= 0 for active particles.
    radius_factor : float
        ``q_max * support_scale`` [-]; the pair radius is
        ``radius_factor * 0.5 * (h_i + h_j) + skin``.
    skin : float
        Verlet skin [m], >= 0.
    dim : int
        2 or 3.
    active : (N,) bool or int array, optional
        Nonzero = active. Inactive particles get empty rows and appear in no
        row. Default: all active.

    Returns
    -------
    NeighbourList
        CSR list (rows sorted ascending, symmetric, no self entries) with
        copies of ``x``, ``h`` and ``active`` and ``n_builds == 1``.

    Notes
    -----
    Cell-linked list + two-pass CSR fill, see the module docstring. Ties at
    exactly the radius are excluded (strict ``<`` on squared distances).
    """
    x, h, act = _check_inputs(x, h, radius_factor, skin, dim, active)
    offsets, idx, idx_buf, cs, n_big = _build_csr(
        x, h, act, float(radius_factor), float(skin), dim)
    return NeighbourList(offsets, idx, x.copy(), h.copy(), skin,
                         radius_factor, dim,
                         None if act is None else act.copy(), 1, cs, n_big)


def max_displacement(nl, x, h):
    """Max displacement and max increase of h since the last build.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64, h : (N,) float64
        Current positions [m] and smoothing lengths [m].

    Returns
    -------
    (float, float)
        ``max_i |x_i - x_ref_i|`` [m] (x, y only in 2D) and
        ``max(0, max_i (h_i - h_ref_i))`` [m], over the particles active at
        the build. NaN gives +inf. Deterministic (max reduction).
    """
    use_active = nl.active_ref is not None
    act = nl.active_ref if use_active else _NO_MASK
    d2, dh = _max_disp_dh(x, nl.x_ref, h, nl.h_ref, act, use_active, nl.dim)
    return math.sqrt(d2), dh


def needs_rebuild(nl, x, h):
    """True when the list may miss a pair that is now within its radius.

    The test is ``2 * max_i |x_i - x_ref_i| + radius_factor *
    max(0, max_i (h_i - h_ref_i)) > skin`` over the particles active at the
    build.

    Why it suffices: let ``d = max |x_i - x_ref_i|`` and ``e = max(0, max
    (h_i - h_ref_i))``. If a pair is within its *current* radius without
    skin, ``|x_i - x_j| < rf * 0.5 * (h_i + h_j)``, then by the triangle
    inequality ``|x_ref_i - x_ref_j| <= |x_i - x_j| + 2 d`` and, since each
    ``h`` grew by at most ``e``, ``rf * 0.5 * (h_i + h_j) <= rf * 0.5 *
    (h_ref_i + h_ref_j) + rf * e``. Hence ``|x_ref_i - x_ref_j| < rf * 0.5 *
    (h_ref_i + h_ref_j) + 2 d + rf * e <= ... + skin`` whenever ``2 d + rf e
    <= skin``: the pair satisfied the build criterion and is in the list.
    (Shrinking ``h`` only shrinks the current radius, so only the increase
    counts.) The argument is exact in real arithmetic; floating-point
    evaluation of the distances can only matter for pairs within a few ulps
    of the radius. The list may contain extra pairs beyond the current
    radius; kernels must still test the distance. Changes of the active set
    are not seen here; ``update_neighbours`` handles them. Inactive
    particles (at the build) are ignored in the maxima, so eroded particles
    flying away do not trigger rebuilds.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64
        Current positions [m].
    h : (N,) float64
        Current smoothing lengths [m].

    Returns
    -------
    bool
    """
    if x.shape[0] != nl.n or h.shape[0] != nl.n:
        return True
    d, dh = max_displacement(nl, x, h)
    return 2.0 * d + nl.radius_factor * dh > nl.skin


def update_neighbours(nl, x, h, dim, active=None):
    """Rebuild ``nl`` in place if needed; return it.

    A rebuild happens when ``needs_rebuild(nl, x, h)``, or when the number of
    particles, ``dim`` or the active mask differ from those of the last build
    (an activated particle would otherwise be missing, a deactivated one
    would remain). On rebuild ``offsets``, ``x_ref``, ``h_ref`` and the
    storage of ``idx`` are overwritten in place when their size allows (no
    allocation of the large arrays, lower peak memory; ``idx`` becomes a
    view of a buffer with up to 10 % spare capacity when it has to grow),
    and ``n_builds`` is incremented. Arrays obtained from ``nl`` before the
    call must not be kept across it.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64, h : (N,) float64
        Current positions [m] and smoothing lengths [m].
    dim : int
        2 or 3.
    active : (N,) bool or int array, optional
        Current active mask (None = all active).

    Returns
    -------
    NeighbourList
        ``nl`` itself (rebuilt or not).
    """
    n = nl.n
    rebuild = (x.shape[0] != n or h.shape[0] != n or dim != nl.dim
               or (active is None) != (nl.active_ref is None))
    if not rebuild and active is not None:
        a = np.asarray(active)
        rebuild = a.shape != (n,) or _mask_changed(a, nl.active_ref)
    if not rebuild:
        rebuild = needs_rebuild(nl, x, h)
    if not rebuild:
        return nl
    x, h, act = _check_inputs(x, h, nl.radius_factor, nl.skin, dim, active)
    offsets, idx, _, cs, n_big = _build_csr(
        x, h, act, nl.radius_factor, nl.skin, dim, nl.offsets,
        _idx_storage(nl.idx))
    nl.offsets = offsets
    nl.idx = idx
    if nl.x_ref.shape == x.shape:
        nl.x_ref[...] = x
        nl.h_ref[...] = h
    else:
        nl.x_ref = x.copy()
        nl.h_ref = h.copy()
    if act is None:
        nl.active_ref = None
    elif nl.active_ref is not None and nl.active_ref.shape == act.shape:
        nl.active_ref[...] = act
    else:
        nl.active_ref = act.copy()
    nl.dim = int(dim)
    nl.cell_size = cs
    nl.n_big = n_big
    nl.n_builds += 1
    return nl


def brute_force_neighbours(x, h, radius_factor, skin, dim, active=None):
    """O(N^2) NumPy reference of ``build_neighbours`` (for tests).

    Evaluates the same floating-point pair test (see module docstring) for
    all pairs, in row blocks to bound memory.

    Returns
    -------
    offsets : (N + 1,) int64
    idx : (nnz,) int32
        Rows sorted ascending.
    """
    x, h, act = _check_inputs(x, h, radius_factor, skin, dim, active)
    n = x.shape[0]
    if act is None:
        act = np.ones(n, dtype=bool)
    half_rf = float(radius_factor) * 0.5
    skin = float(skin)
    rows, cols = [], []
    block = max(1, 2_000_000 // max(n, 1))
    for i0 in range(0, n, block):
        i1 = min(n, i0 + block)
        d0 = x[i0:i1, None, 0] - x[None, :, 0]
        d1 = x[i0:i1, None, 1] - x[None, :, 1]
        d2 = d0 * d0 + d1 * d1
        if dim == 3:
            dz = x[i0:i1, None, 2] - x[None, :, 2]
            d2 = d2 + dz * dz
        r = half_rf * (h[i0:i1, None] + h[None, :]) + skin
        m = d2 < r * r
        m &= act[i0:i1, None] & act[None, :]
        m[np.arange(i1 - i0), np.arange(i0, i1)] = False
        ri, ci = np.nonzero(m)
        rows.append(ri + i0)
        cols.append(ci)
    ri = np.concatenate(rows) if rows else np.empty(0, dtype=np.int64)
    ci = np.concatenate(cols) if cols else np.empty(0, dtype=np.int64)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(ri, minlength=n), out=offsets[1:])
    return offsets, ci.astype(np.int32)


def max_neighbours(nl):
    """Largest row length of the list (0 for an empty list)."""
    if nl.n == 0:
        return 0
    return int(np.diff(nl.offsets).max())


def mean_neighbours(nl):
    """Mean row length over the particles active at the build (0.0 if none)."""
    n_act = nl.n if nl.active_ref is None else int(nl.active_ref.sum())
    if n_act == 0:
        return 0.0
    return nl.nnz / n_act
