"""Cell binning of the neighbour search: grid size, counting sort, stencil.

The uniform grid of step 3 of the algorithm (see :mod:`sphdyn.neighbours`):
``_grid_setup`` chooses the cell size, origin and cells per axis and splits
off the large-h particles; ``_bin_particles`` sorts the grid particles by
cell (counting sort, positions copied in cell order); ``_stencil`` gives the
range of cells a particle scans.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Relative enlargement of the cell size over the largest grid pair radius:
# guarantees |c_i - c_j| <= k along each axis despite rounding in
# floor((x - lo) / cs) for up to ~1e9 cells per axis.
_MARGIN = 1e-6
# At most this many large-h particles are kept out of the grid.
_BIG_MAX = 64
# ... and only if it shrinks the grid pair radius by at least this factor.
_BIG_RADIUS_RATIO = 1.5


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
