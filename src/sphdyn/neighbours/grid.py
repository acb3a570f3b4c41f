"""Cell binning of the neighbour search: grid size, counting sort, stencil.

The uniform grids of steps 2-4 of the algorithm (see
:mod:`sphdyn.neighbours`): ``_choose_h_cut`` splits the particles by h into
a fine and a coarse grid (or keeps one); ``_make_grid`` sizes a grid over its
particles' box (``_grid_shape``) and sorts them by cell (``_bin_particles``:
counting sort, positions copied in cell order); ``_stencil`` gives the range
of cells a particle scans.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Relative enlargement of the cell size over the largest grid pair radius:
# guarantees |c_i - c_j| <= k along each axis despite rounding in
# floor((x - lo) / cs) for up to ~1e9 cells per axis.
_MARGIN = 1e-6
# The particles are split into a fine and a coarse grid by h only if the
# largest pair radius exceeds the smallest by this factor (else one grid) ...
_SPLIT_MIN_RATIO = 1.05
# ... at the best of this many equally spaced thresholds in h.
_SPLIT_BINS = 32
# Cost of scanning one row of cells, in pair tests (the split's estimate).
_ROW_COST = 4.0
# A split is taken only if its estimated cost is below this share of one
# grid's: the estimate leaves out the work per neighbour found (the same
# either way) and assumes a uniform cloud, so it overstates the gain (a
# cloud with h log-uniform over a factor 2: 2 % estimated, 10 % slower
# measured; the blast slab's products: 54 % estimated, 50 % measured).
_SPLIT_GAIN = 0.75


@njit(cache=True, error_model="numpy")
def _cell_coord(xa, lo, inv_cs, n):
    """Cell index along one axis, clamped to [0, n - 1] (before the integer
    conversion: a particle far outside the grid's box is clamped too)."""
    c = math.floor((xa - lo) * inv_cs)
    if c < 0.0:
        return 0
    if c > n - 1:
        return n - 1
    return int(c)


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
def _stencil(i, x, h, dim, half_rf, skin, r_grid, lo, inv_cs, nc, h_top):
    """Cell ranges ``(x0, x1, y0, y1, z0, z1)`` (inclusive) of a grid
    scanned by ``i``.

    ``k = 1`` cell around the own cell when the largest pair radius of ``i``
    with a particle of the grid, ``rf * 0.5 * (h_i + h_top) + skin``
    (``h_top``: the grid's largest h), is not larger than ``r_grid`` (true
    for the grid's own particles), else ``k = ceil(r_i (1 + 2e-6) / cs)``.
    """
    nx, ny, nz = nc[0], nc[1], nc[2]
    r_i = half_rf * (h[i] + h_top) + skin
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


def _grid_shape(ext, r_grid, n_grid, dim):
    """Cell size and cells per axis of a grid over the extent ``ext`` (3,)
    [m] whose largest pair radius is ``r_grid`` [m].

    ``cs = r_grid (1 + 1e-6)``, enlarged until the grid has at most
    ``4 n_grid + 64`` cells (sparse clouds, far-apart bodies).
    """
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
    return cs, np.array([int(v) for v in ncf], dtype=np.int64)


def _bounds(xg, dim):
    """Lower corner (3,) and extent (3,) [m] of the positions ``xg`` (n, 3)."""
    lo = np.zeros(3)
    ext = np.zeros(3)
    for a in range(dim):  # per column: NumPy's axis-0 reduction of the
        col = xg[:, a]    # strided (n, dim) view is 20x slower
        lo[a] = col.min()
        ext[a] = col.max() - lo[a]
    return lo, ext


def _split_cost(n, n_big, h_cut, h_max, rf, skin, dim, vol):
    """Estimated cost of a build whose fine grid holds the ``n - n_big``
    particles with ``h <= h_cut`` and whose coarse grid the ``n_big`` others
    (arrays of candidates), in pair tests, for particles spread uniformly
    over the volume ``vol``.

    Per particle: the candidates of the cells it scans (cells of side ``r =
    rf h_top + skin``, ``occ = n_grid r^dim / vol`` particles each; ``3^dim``
    cells, ``(2k + 1)^dim`` for a coarse-grid particle in the fine grid, ``k
    = ceil(r_ij / r_fine)``) plus ``_ROW_COST`` tests per row of cells.
    """
    n_f = n - n_big
    r_f = rf * h_cut + skin
    r_c = rf * h_max + skin
    occ_f = n_f * r_f**dim / vol
    occ_c = n_big * r_c**dim / vol
    k_b = np.ceil((0.5 * rf * (h_max + h_cut) + skin) / r_f)
    s = 2.0 * k_b + 1.0
    cost = (n_f * (3.0**dim * occ_f + 3.0**(dim - 1) * _ROW_COST)
            + n_big * (s**dim * occ_f + s**(dim - 1) * _ROW_COST))
    return cost + np.where(n_big > 0, n * (3.0**dim * occ_c
                                           + 3.0**(dim - 1) * _ROW_COST), 0.0)


def _choose_h_cut(ha, xa, rf, skin, dim):
    """Largest ``h`` of the fine grid: the split of the particles by ``h``
    into a fine and a coarse grid of least :func:`_split_cost`.

    ``ha`` (n,) are the active particles' h [m], ``xa`` (n, 3) their
    positions [m]; the cloud's volume is that of the box holding the middle
    98 % of them along each axis (a few far-flung particles do not dilute
    the estimated density).
    Candidate thresholds: ``_SPLIT_BINS`` equal steps between the smallest
    and the largest h (the largest: one grid). No split when the largest
    pair radius is within ``_SPLIT_MIN_RATIO`` of the smallest, or when the
    best split's cost is above ``_SPLIT_GAIN`` times one grid's. Returns
    ``(h_cut, big_mask)``, ``big_mask`` None for one grid.
    """
    h_min = float(ha.min())
    h_max = float(ha.max())
    if not rf * h_max + skin > _SPLIT_MIN_RATIO * (rf * h_min + skin):
        return h_max, None
    n = ha.shape[0]
    counts, edges = np.histogram(ha, bins=_SPLIT_BINS, range=(h_min, h_max))
    edges = edges[1:]
    edges[-1] = h_max
    n_big = n - np.cumsum(counts)  # ~ #(h > edge): ties at an edge aside
    r_c = rf * h_max + skin
    vol = 1.0
    for a in range(dim):
        q0, q1 = np.quantile(xa[:, a], [0.01, 0.99])
        vol *= max(float(q1 - q0), r_c)
    cost = _split_cost(n, n_big.astype(np.float64), edges, h_max, rf, skin,
                       dim, vol)
    best = int(np.argmin(cost))
    t = float(edges[best])
    if t >= h_max or cost[best] > _SPLIT_GAIN * cost[-1]:
        return h_max, None
    big_mask = ha > t
    return float(ha[~big_mask].max()), big_mask


def _make_grid(x, h, ids, h_top, half_rf, skin, dim, box=None):
    """The grid of the particles ``ids`` (ascending int64), whose largest h
    is ``h_top`` [m], over their own bounding box (``box = (lo, ext)`` if
    known, :func:`_bounds`).

    Returns ``(grid, cs)``: ``grid = (lo, inv_cs, nc, r_grid, h_top,
    cell_start, order, xs, ys, zs, hs)`` as the row loops take it
    (:mod:`.rows`; ``r_grid = rf * 0.5 * (h_top + h_top) + skin``, the same
    expression as the pair test) and the cell size ``cs`` [m]. No particles:
    one empty cell.
    """
    if ids.shape[0] == 0:
        e = np.empty(0)
        return (np.zeros(3), 1.0, np.ones(3, dtype=np.int64), 0.0, 0.0,
                np.zeros(2, dtype=np.int64), np.empty(0, dtype=np.int32),
                e, e, e, e), 0.0
    lo, ext = _bounds(x[ids], dim) if box is None else box
    r_grid = half_rf * (h_top + h_top) + skin
    cs, nc = _grid_shape(ext, r_grid, ids.shape[0], dim)
    cell_start, order, xs, ys, zs, hs = _bin_particles(x, h, ids, lo,
                                                       1.0 / cs, nc, dim)
    return (lo, 1.0 / cs, nc, r_grid, h_top, cell_start, order, xs, ys, zs,
            hs), cs
