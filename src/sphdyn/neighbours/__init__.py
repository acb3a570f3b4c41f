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
2. *Split by h* (``grid._choose_h_cut``). When ``h`` varies (largest pair
   radius ``rf*h_max + skin`` more than ``_SPLIT_MIN_RATIO = 1.05`` times
   the smallest), the particles with ``h > t`` go to a second, coarse grid
   and the rest to the fine grid, whose cells are then sized by
   ``h_cut = max{h <= t}`` instead of ``h_max``. The threshold ``t`` is the
   best of 32 equal steps between ``h_min`` and ``h_max`` by an estimate of
   the candidate tests (uniform cloud, ``_split_cost``); a split is taken
   only if that estimate is below ``_SPLIT_GAIN = 0.75`` of one grid's.
   Without it, a few large-h particles (explosive products, eroded
   elements' particles, a graded spacing) set the cell size of every
   particle: ``(h_max/h)^dim`` times more candidates per cell.
3. Each grid is uniform over its own particles' box with cell size
   ``cs >= (rf*h_top + skin) * (1 + 1e-6)`` (``h_top`` its largest h: the
   largest pair radius among its particles, with a margin covering rounding
   in the cell-index computation). If a grid would have more than
   ``4 * n_grid + 64`` cells (very sparse clouds, far-apart bodies) its cell
   size is enlarged until it does not. Degenerate extents (line, plane,
   single point) give one cell along the flat axes. Cell indices of a
   particle outside a grid's box are clamped to the box (its true stencil's
   cells within the box are among the clamped stencil's).
4. Counting sort of each grid's particles by flat cell index (stable:
   ascending particle index within a cell); positions and ``h`` are copied
   in cell order so that the candidate loop reads contiguous memory, and
   cells along x are contiguous so each (y, z) row of the stencil is one
   index range.
5. Rows, two passes in ``prange`` over particles visited in cell order
   (fine grid, then coarse; cache locality). Particle ``i`` scans, in each
   grid, the cells within ``k_i`` cells of its own (``k_i = 1`` when its
   largest pair radius with the grid, ``r_i = rf*0.5*(h_i + h_top) +
   skin``, fits the grid's cells: always in the coarse grid and for the
   fine grid's own particles; else ``k_i = ceil(r_i / cs)``).
   (a) Count: branch-free, vectorised candidate loop -> ``counts`` (``i``
   itself, found in its grid, subtracted with the same test); prefix sum ->
   ``offsets``. (b) Fill: candidates in blocks of 64 give a hit bit mask
   (vectorised), set bits are visited with count-trailing-zeros and the
   hits other than ``i`` collected in a per-chunk scratch buffer, then
   stored sorted into ``idx[offsets[i]:offsets[i+1]]`` (rank sort for rows
   <= 128 entries, heap sort above). Every pair is examined from both ends;
   each row is written only by its own iteration (gather form, race free).
   A row whose length differed between the passes (impossible: identical
   expressions) would raise ``RuntimeError`` rather than write out of
   bounds.

Cost: ``O(N * 3^dim * (n_per_fine_cell + n_per_coarse_cell) + n_coarse *
(2k + 1)^dim * n_per_fine_cell)`` per build; memory ``O(N + n_cells +
nnz)``.

Limitations: two grids. An ``h`` spread over several scales (a
fine-to-coarse graded spacing over a factor 10 or more) still scans more
candidates than a tree or a grid per scale would. Clouds whose bounding box
is huge compared to the particle spacing (hit the cell cap) also scan more
candidates per cell.

Modules
-------
``grid``       cell size, counting sort of the particles by cell, stencil
``rows``       candidate loops of one row (count, collect)
``build``      input checks, the two CSR passes, sorted row storage
``verlet``     ``NeighbourList``, ``build_neighbours``, skin checks, rebuilds
``reference``  ``brute_force_neighbours`` (O(N^2), for tests)
``stats``      ``max_neighbours``, ``mean_neighbours``

The model and its tests: docs/theory.md, "Neighbour search".
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
