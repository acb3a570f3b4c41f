"""Generated meshes: boxes of hex8 / quad4 (uniform or graded), prisms of a
polygon, and lines of line2 elements (:class:`~sphdyn.geometry.mesh.MeshData`;
node order and kinds: :mod:`sphdyn.geometry.mesh`)."""

from __future__ import annotations

import numpy as np

from .lattice import (PRISM_PLANES, _RTOL, _check_dim, _count, _point, _positive,
                      polygon_contains, prism_section)
from .mesh import MeshData
from .shapes import corner_signs

__all__ = ["GRADED_FROM", "block_mesh", "graded_nodes", "line_mesh", "polyline_mesh",
           "prism_mesh"]


def _divisions(divisions, dim: int) -> tuple[int, ...]:
    try:
        n = tuple(int(v) for v in divisions)
        ok = len(n) == dim and all(v >= 1 and v == w for v, w in zip(n, divisions))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"divisions must be {dim} positive integers (elements along "
                         f"{'x, y, z' if dim == 3 else 'x, y'}), got {divisions!r}")
    return n


#: where a graded axis has its smallest elements
GRADED_FROM = ("lo", "hi", "centre")


def graded_nodes(lo: float, hi: float, n: int, ratio: float = 1.0,
                 smallest: str = "lo") -> np.ndarray:
    r"""Node coordinates (n + 1,) [m] of ``n`` elements from ``lo`` to ``hi``
    whose sizes grow geometrically away from ``smallest`` ("lo", "hi" or
    "centre") by a constant factor, the largest ``ratio`` times the smallest:
    :math:`s_i = s_0 q^{k_i}`, :math:`q = \mathrm{ratio}^{1/k_{max}}`, with
    :math:`k_i` element i's distance in elements from the smallest one(s)
    (:math:`k_i = |i - (n-1)/2| - \min_j |j - (n-1)/2|` for "centre": the
    middle element, or the middle two, smallest; two elements stay equal)
    and :math:`s_0` set by :math:`\sum s_i = hi - lo` (a bias, as LS-DYNA's
    and Gmsh's progressions). ``ratio = 1``: equal elements, the same bits
    as ``numpy.linspace``; the ends are ``lo`` and ``hi`` exactly."""
    if ratio == 1.0 or n == 1:
        return np.linspace(lo, hi, n + 1)
    i = np.arange(n, dtype=float)
    k = {"lo": i, "hi": n - 1 - i, "centre": np.abs(i - 0.5 * (n - 1))}[smallest]
    k -= k.min()
    if k.max() == 0.0:  # two elements about the centre: equal
        return np.linspace(lo, hi, n + 1)
    sizes = ratio ** (k / k.max())
    x = lo + (hi - lo) * np.concatenate(([0.0], np.cumsum(sizes))) / sizes.sum()
    x[-1] = hi
    return x


def block_mesh(lo, hi, divisions, dim: int, grading=None) -> MeshData:
    """Structured mesh of an axis-aligned box: hex8 in 3D, quad4 in 2D.

    Parameters
    ----------
    lo, hi : array_like, (3,) (or (2,) in 2D)
        Opposite corners [m], ``hi > lo`` on every used axis; z is ignored
        in 2D.
    divisions : sequence of int
        ``(nx, ny, nz)`` in 3D, ``(nx, ny)`` in 2D: elements per axis.
    dim : {2, 3}
    grading : None (equal elements), or one ``(ratio, smallest)`` per axis:
        :func:`graded_nodes` (``(1.0, "lo")``: equal elements on that axis).

    Returns
    -------
    MeshData
        ``prod(n_a + 1)`` nodes and ``prod(n_a)`` elements, of equal size
        unless graded.
        Nodes and elements are numbered in grid-index order, x slowest
        (``numpy.meshgrid(..., indexing="ij")``, as the particle lattices);
        ids 1-based consecutive. Sets: element set ``"all"``; node sets
        ``"all"``, ``"xmin"``, ``"xmax"``, ``"ymin"``, ``"ymax"`` and in 3D
        ``"zmin"``, ``"zmax"`` (the nodes on each face).
    """
    dim = _check_dim(dim)
    lo, hi = _point(lo, dim, "lo"), _point(hi, dim, "hi")
    n = _divisions(divisions, dim)
    if np.any(hi[:dim] <= lo[:dim]):
        raise ValueError(f"block hi must be > lo on every axis, got lo={lo[:dim]}, hi={hi[:dim]}")
    grading = [(1.0, "lo")] * dim if grading is None else list(grading)
    if len(grading) != dim or any(r < 1.0 or w not in GRADED_FROM for r, w in grading):
        raise ValueError(f"grading must give {dim} (ratio >= 1, one of {GRADED_FROM}) pairs, "
                         f"got {grading!r}")
    axes = [graded_nodes(lo[a], hi[a], n[a], *grading[a]) for a in range(dim)]
    grid = np.meshgrid(*axes, indexing="ij")
    points = np.zeros((grid[0].size, 3))
    for a in range(dim):
        points[:, a] = grid[a].reshape(-1)
    node = np.arange(points.shape[0], dtype=np.int64).reshape([m + 1 for m in n])
    kind = "hex8" if dim == 3 else "quad4"
    # grid offsets of the corners in node order = the corner natural coordinates
    offsets = ((corner_signs(dim) + 1) / 2).astype(np.int64)
    cells = np.stack([node[tuple(slice(o[a], o[a] + n[a]) for a in range(dim))].reshape(-1)
                      for o in offsets], axis=1)
    node_sets = {"all": node.reshape(-1)}
    for a, axis in enumerate("xyz"[:dim]):
        node_sets[f"{axis}min"] = np.take(node, 0, axis=a).reshape(-1)
        node_sets[f"{axis}max"] = np.take(node, -1, axis=a).reshape(-1)
    return MeshData(points, cells, kind, node_sets=node_sets,
                    element_sets={"all": np.arange(cells.shape[0])},
                    source=f"block_mesh({dim}D box)")


def prism_mesh(points, element_size: float, dim: int, axis="z", base: float = 0.0,
               length=None) -> MeshData:
    """Structured mesh of a prism: the cells of a grid over a polygon that lie
    in it, extruded along an axis (hex8; quad4 of the polygon itself in 2D).
    An I-, T- or L-section member meshed like the particles of the
    ``prism`` body shape (:func:`~sphdyn.geometry.lattice.prism_lattice`).

    Parameters
    ----------
    points : (k, 2) array_like, k >= 3
        Polygon vertices [m] in order, in the plane normal to ``axis``:
        (x, y) for "z", (y, z) for "x", (z, x) for "y".
    element_size : float
        Nominal element edge [m]: each direction of the polygon's bounding box
        (and the extrusion) gets the nearest whole number of equal elements.
    dim : {2, 3}
        In 2D the axis must be "z" and ``length`` absent.
    axis, base, length
        3D: the prism spans ``[base, base + length]`` along the axis [m].

    Returns
    -------
    MeshData
        The elements of the block mesh of the bounding box whose centroids lie
        in the polygon (within 1e-9 of its size), the nodes they use
        (renumbered in grid order). With ``element_size`` equal to a particle
        spacing ``dx`` and the extents whole multiples of it, the centroids
        are the particles of the ``prism`` lattice; with the vertices on the
        grid, the mesh fills the polygon
        exactly (else it is the staircase of the cells whose centres are in).
        Sets: ``"all"`` (nodes and elements), ``"<axis>min"``/``"<axis>max"``
        for the extrusion's end faces (3D).
    """
    dim = _check_dim(dim)
    size = _positive("element_size", element_size)
    poly, ax = prism_section(points, dim, axis, length)
    pu, pv = PRISM_PLANES[ax]
    lo, hi, n = np.zeros(3), np.zeros(3), [1, 1, 1]
    (lo[pu], lo[pv]), (hi[pu], hi[pv]) = poly.min(axis=0), poly.max(axis=0)
    if dim == 3:
        lo[ax], hi[ax] = float(base), float(base) + _positive("length", length)
    for a in range(dim):
        n[a] = _count(hi[a] - lo[a], size)
    box = block_mesh(lo, hi, n[:dim], dim)
    centres = box.points[box.cells].mean(axis=1)
    extent = max(float(np.max(hi[:dim] - lo[:dim])), size)
    keep = polygon_contains(poly, centres[:, [pu, pv]], _RTOL * extent)
    if not keep.any():
        raise ValueError(f"no element of size {size} m has its centre in the polygon")
    cells = box.cells[keep]
    used = np.unique(cells)
    renumber = np.full(box.n_nodes, -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    node_sets = {"all": np.arange(used.size)}
    if dim == 3:
        name = "xyz"[ax]
        for end, value in (("min", lo[ax]), ("max", hi[ax])):
            on = np.isclose(box.points[used, ax], value, rtol=0.0, atol=_RTOL * extent)
            node_sets[f"{name}{end}"] = np.flatnonzero(on)
    return MeshData(box.points[used], renumber[cells], box.kind, node_sets=node_sets,
                    element_sets={"all": np.arange(cells.shape[0])},
                    source=f"prism_mesh({dim}D, {poly.shape[0]}-gon)")


def line_mesh(start, end, n: int) -> MeshData:
    """A straight line of ``n`` equal line2 elements (a beam or truss).

    Parameters
    ----------
    start, end : array_like, (3,) or (2,)
        End points [m] (z = 0 when given with two components), distinct.
    n : int
        Number of elements, >= 1.

    Returns
    -------
    MeshData
        ``n + 1`` nodes from ``start`` to ``end``, element ``k`` joining nodes
        ``k`` and ``k + 1``; ids 1-based consecutive. Sets: element set
        ``"all"``; node sets ``"all"``, ``"start"`` (node 0), ``"end"``
        (node n).
    """
    return polyline_mesh([start, end], [n])


def polyline_mesh(points, counts, closed: bool = False, copies: int = 1,
                  step=(0.0, 0.0, 0.0)) -> MeshData:
    """Line2 elements along a polyline (a bent bar, a closed stirrup), optionally
    repeated at a constant step (stirrups along a beam).

    Parameters
    ----------
    points : array_like, (P, 3) or (P, 2)
        Corner points [m], P >= 2 (>= 3 if ``closed``); consecutive points
        distinct (and the last distinct from the first if ``closed``).
    counts : sequence of int
        Equal elements on each segment (P - 1 segments, P if ``closed``: the
        last joins the last point to the first).
    closed : bool
        Join the last point to the first (a loop).
    copies : int
        Number of copies, >= 1; copy ``k`` is shifted by ``k * step``.
    step : array_like, (3,) or (2,)
        Shift between copies [m] (must not be zero when ``copies > 1``).

    Returns
    -------
    MeshData
        Segments share their corner nodes; copies share nothing. Node ``0`` of
        a copy is its first point. Element set ``"all"``; node sets ``"all"``,
        ``"start"`` (each copy's first node), ``"end"`` (each copy's last node;
        the first one for a closed loop).
    """
    dim = 2 if np.ndim(points) == 2 and np.shape(points)[1] == 2 else 3
    pts = [_point(p, dim, f"points[{k}]") for k, p in enumerate(points)]
    segs = len(pts) if closed else len(pts) - 1
    if len(pts) < (3 if closed else 2):
        raise ValueError(f"a {'closed ' if closed else ''}polyline needs at least "
                         f"{3 if closed else 2} points, got {len(pts)}")
    if len(counts) != segs:
        raise ValueError(f"counts needs one element count per segment ({segs}), "
                         f"got {len(counts)}")
    for n in counts:
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"n must be a positive integer (number of elements), got {n!r}")
    if isinstance(copies, bool) or not isinstance(copies, (int, np.integer)) or copies < 1:
        raise ValueError(f"copies must be a positive integer, got {copies!r}")
    shift = _point(step, dim, "step")
    if copies > 1 and not np.any(shift):
        raise ValueError("copies of a polyline need a nonzero step between them")
    rows = []
    for s in range(segs):
        p0, p1 = pts[s], pts[(s + 1) % len(pts)]
        if np.array_equal(p0, p1):
            raise ValueError(f"line start and end must differ, got {p0} twice "
                             f"(segment {s})")
        t = np.linspace(0.0, 1.0, counts[s] + 1)[:-1, None]
        rows.append(p0 + t * (p1 - p0))
    if not closed:
        rows.append(pts[-1][None, :])
    one = np.concatenate(rows)  # corner points exactly as given
    n = one.shape[0]
    e = int(sum(counts))
    first = np.arange(e)
    cells = np.stack([first, (first + 1) % n if closed else first + 1], axis=1)
    points_all = np.concatenate([one + k * shift for k in range(copies)])
    cells_all = np.concatenate([cells + k * n for k in range(copies)])
    starts = np.arange(copies) * n
    ends = starts + (0 if closed else n - 1)
    return MeshData(points_all, cells_all, "line2",
                    node_sets={"all": np.arange(n * copies), "start": starts,
                               "end": ends},
                    element_sets={"all": np.arange(e * copies)}, source="polyline_mesh")
