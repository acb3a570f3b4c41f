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

Modules
-------
``grid``       cell size, counting sort of the particles by cell, stencil
``rows``       candidate loops of one row (count, collect)
``build``      input checks, the two CSR passes, sorted row storage
``verlet``     ``NeighbourList``, ``build_neighbours``, skin checks, rebuilds
``reference``  ``brute_force_neighbours`` (O(N^2), for tests)
``stats``      ``max_neighbours``, ``mean_neighbours``
"""

from __future__ import annotations

from .reference import brute_force_neighbours
from .stats import max_neighbours, mean_neighbours
from .verlet import (NeighbourList, build_neighbours, max_displacement,
                     needs_rebuild, update_neighbours)

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
