"""Finite-element meshes: generated boxes and lines, and meshes read from files.

A mesh is a :class:`MeshData`: node positions ``points`` (N, 3) float64 in
metres (2D = plane strain in the x-y plane, ``z = 0``), connectivity
``cells`` (E, nen) int64 of 0-based node indices, one element kind per mesh,
and named node and element sets.

Element kinds and node order (VTK's, which is also LS-DYNA's, Gmsh's and
Abaqus's for these linear elements, and meshio's):

* ``"hex8"`` (3D): nodes 0-3 on the bottom face (zeta = -1) counter-clockwise
  seen from +z, at natural coordinates (-,-,-), (+,-,-), (+,+,-), (-,+,-);
  nodes 4-7 the same on the top face (zeta = +1);
* ``"quad4"`` (2D): (-,-), (+,-), (+,+), (-,+), counter-clockwise;
* ``"line2"`` (beams, trusses; 2D or 3D): start, end.

In this order a right-handed (undistorted) element has a positive Jacobian
determinant at every corner (:func:`element_jacobians`).

Files are read with :mod:`meshio`'s format readers (``meshio.gmsh.read``,
``meshio.abaqus.read``; not ``meshio.read``, which ends the process on a read
error): Gmsh ``.msh`` (formats 2.2 and 4.1) and Abaqus ``.inp``. meshio 5.3
does not know the Abaqus plane-strain quads (``CPE4``, ``CPE4R``, ...); this
module registers them with meshio's Abaqus reader as ``quad`` when it is
imported.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np

from .lattice import (PRISM_PLANES, _RTOL, _check_dim, _count, _point, _positive,
                      polygon_contains, prism_section)
from .shapes import corner_signs, shape_derivatives

__all__ = [
    "MESH_KINDS",
    "MeshData",
    "block_mesh",
    "line_mesh",
    "polyline_mesh",
    "prism_mesh",
    "read_mesh",
    "element_jacobians",
    "check_elements",
]

#: element kind -> (nodes per element, topological dimension)
MESH_KINDS = {"hex8": (8, 3), "quad4": (4, 2), "line2": (2, 1)}

# kinds a mesh of spatial dimension dim may hold
_KINDS_IN = {2: ("quad4", "line2"), 3: ("hex8", "line2")}
# meshio cell type <-> kind
#: element kind <-> meshio cell type (= the VTK cell: hexahedron 12, quad 9, line 3)
TO_MESHIO = {"hex8": "hexahedron", "quad4": "quad", "line2": "line"}
_FROM_MESHIO = {v: k for k, v in TO_MESHIO.items()}
# file extension -> (meshio format, label, reader)
_FORMATS = {".msh": ("gmsh", "Gmsh", meshio.gmsh.read),
            ".inp": ("abaqus", "Abaqus", meshio.abaqus.read)}

# Thresholds of check_elements (relative, see its docstring).
_DEGENERATE_RTOL = 1e-6
_ZERO_RTOL = 1e-12
_MAX_IDS = 10


def _register_abaqus_plane_strain() -> None:
    """Teach meshio's Abaqus reader the 4-node plane-strain elements (as quad)."""
    try:
        from meshio.abaqus import _abaqus
    except ImportError:  # pragma: no cover - another meshio layout
        return
    for name in ("CPE4", "CPE4R", "CPE4H", "CPE4RH", "CPE4I", "CPE4IH"):
        _abaqus.abaqus_to_meshio_type.setdefault(name, "quad")


_register_abaqus_plane_strain()


# --------------------------------------------------------------------------
# the mesh
# --------------------------------------------------------------------------
def _index_array(a, name: str, n: int, label: str) -> np.ndarray:
    """Sorted unique int64 indices in [0, n)."""
    a = np.unique(np.asarray(a, dtype=np.int64).reshape(-1))
    if a.size and (a[0] < 0 or a[-1] >= n):
        raise ValueError(f"{label}: set {name!r} holds indices outside [0, {n})")
    return a


@dataclass
class MeshData:
    """A finite-element mesh of one element kind.

    Attributes
    ----------
    points : (N, 3) float64
        Node positions [m]; ``z = 0`` in 2D.
    cells : (E, nen) int64
        Connectivity, 0-based node indices in the node order of the module
        docstring (``nen`` = 8, 4, 2 for hex8, quad4, line2).
    kind : str
        ``"hex8"``, ``"quad4"`` or ``"line2"`` (:data:`MESH_KINDS`).
    node_sets : dict[str, (n,) int64]
        Named node sets, sorted unique node indices.
    element_sets : dict[str, (m,) int64]
        Named element sets, sorted unique element indices.
    element_ids, node_ids : (E,) and (N,) int64
        The ids the user knows the elements and nodes by: the file's tags
        (see :func:`read_mesh`), 1-based consecutive for generated meshes
        (the default). Error messages name these.
    source : str
        What the mesh came from (a file path or the generator), for messages.
    """

    points: np.ndarray
    cells: np.ndarray
    kind: str
    node_sets: dict = field(default_factory=dict)
    element_sets: dict = field(default_factory=dict)
    element_ids: np.ndarray | None = None
    node_ids: np.ndarray | None = None
    source: str = ""

    def __post_init__(self):
        label = self.label
        if self.kind not in MESH_KINDS:
            raise ValueError(f"{label}: kind must be one of {sorted(MESH_KINDS)}, "
                             f"got {self.kind!r}")
        nen = MESH_KINDS[self.kind][0]
        self.points = np.ascontiguousarray(self.points, dtype=np.float64)
        self.cells = np.ascontiguousarray(self.cells, dtype=np.int64)
        if self.points.ndim != 2 or self.points.shape[1] != 3:
            raise ValueError(f"{label}: points must have shape (N, 3), got {self.points.shape}")
        if self.cells.ndim != 2 or self.cells.shape[1] != nen:
            raise ValueError(f"{label}: {self.kind} cells must have shape (E, {nen}), "
                             f"got {self.cells.shape}")
        n, e = self.points.shape[0], self.cells.shape[0]
        if self.cells.size and (self.cells.min() < 0 or self.cells.max() >= n):
            raise ValueError(f"{label}: cells refer to nodes outside [0, {n})")
        if not np.all(np.isfinite(self.points)):
            raise ValueError(f"{label}: node positions must be finite")
        for attr, count in (("node_ids", n), ("element_ids", e)):
            ids = getattr(self, attr)
            ids = np.arange(1, count + 1) if ids is None else np.asarray(ids, dtype=np.int64)
            if ids.shape != (count,):
                raise ValueError(f"{label}: {attr} must have shape ({count},), got {ids.shape}")
            setattr(self, attr, ids)
        self.node_sets = {k: _index_array(v, k, n, label) for k, v in self.node_sets.items()}
        self.element_sets = {k: _index_array(v, k, e, label) for k, v in self.element_sets.items()}

    @property
    def label(self) -> str:
        return f"mesh {self.source}" if self.source else "mesh"

    @property
    def n_nodes(self) -> int:
        return self.points.shape[0]

    @property
    def n_elements(self) -> int:
        return self.cells.shape[0]

    def node_set(self, name: str) -> np.ndarray:
        """(n,) int64 node indices of the node set ``name`` (ValueError if absent)."""
        return self._set(self.node_sets, name, "node")

    def element_set(self, name: str) -> np.ndarray:
        """(m,) int64 element indices of the element set ``name`` (ValueError if absent)."""
        return self._set(self.element_sets, name, "element")

    def _set(self, sets: dict, name: str, what: str) -> np.ndarray:
        if name not in sets:
            raise ValueError(f"{self.label}: no {what} set named {name!r}; available {what} "
                             f"sets: {', '.join(map(repr, sorted(sets))) or 'none'} "
                             "(names are case-sensitive)")
        return sets[name]


# --------------------------------------------------------------------------
# Jacobians and element checks
# --------------------------------------------------------------------------
def element_jacobians(points, cells, kind: str) -> np.ndarray:
    """Jacobian determinant of each element at each of its corner nodes.

    For hex8 and quad4 this is ``det J`` of the isoparametric map
    ``x(xi) = sum_a N_a(xi) x_a`` (trilinear / bilinear ``N_a``, natural
    coordinates in [-1, 1]^d), ``J_ij = dx_i / dxi_j``, evaluated at the
    corner ``xi_a`` (Hughes, *The Finite Element Method*, 2000, sec. 3.5);
    quad4 uses x and y only. ``det J > 0`` at all corners means a valid,
    right-handed element; the element volume is ``integral det J dxi``
    (a rectangular box of volume V has ``det J = V / 2**d`` everywhere).
    For line2 the entry is the element length (both nodes), which cannot be
    negative.

    Parameters
    ----------
    points : (N, 3) array_like
        Node positions [m].
    cells : (E, nen) array_like of int
        Connectivity (0-based, node order of the module docstring).
    kind : {"hex8", "quad4", "line2"}

    Returns
    -------
    det : (E, nen) float64
        [m^3] (hex8), [m^2] (quad4), [m] (line2).
    """
    if kind not in MESH_KINDS:
        raise ValueError(f"kind must be one of {sorted(MESH_KINDS)}, got {kind!r}")
    x = np.asarray(points, dtype=np.float64)[np.asarray(cells, dtype=np.int64)]  # (E, nen, 3)
    if kind == "line2":
        length = np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
        return np.repeat(length[:, None], 2, axis=1)
    d = MESH_KINDS[kind][1]
    grad = shape_derivatives(d, corner_signs(d))         # (corner p, node a, j)
    jac = np.einsum("eai,paj->epij", x[:, :, :d], grad)  # (E, nen, d, d)
    return np.linalg.det(jac)


def _ids_text(ids: np.ndarray) -> str:
    shown = ", ".join(str(i) for i in ids[:_MAX_IDS])
    return shown + (f" and {ids.size - _MAX_IDS} more" if ids.size > _MAX_IDS else "")


def check_elements(mesh: MeshData) -> None:
    """Refuse a mesh with inverted or degenerate elements.

    With ``det`` the corner determinants of :func:`element_jacobians`, the
    mean ``m = mean_a |det_a|`` and the radius ``h`` of an element (largest
    node distance from its centroid), an element is

    * *degenerate* if it has (nearly) zero volume, ``m <= 1e-12 h**d``
      (d = 3, 2, 1 for hex8, quad4, line2) or ``h`` below ``1e-12`` times the
      mesh's bounding-box diagonal, or if ``min_a det_a`` lies in
      ``[-1e-6 m, 1e-6 m]`` (a corner collapsed: coincident or repeated nodes);
    * *inverted* if ``min_a det_a < -1e-6 m`` (a corner determinant below
      zero: the element is turned inside out, usually by a mirrored node
      order).

    Parameters
    ----------
    mesh : MeshData

    Raises
    ------
    ValueError
        Naming up to 10 element ids (``mesh.element_ids``) of each problem and
        the likely fix.
    """
    if mesh.n_elements == 0:
        return
    det = element_jacobians(mesh.points, mesh.cells, mesh.kind)
    x = mesh.points[mesh.cells]
    h = np.linalg.norm(x - x.mean(axis=1, keepdims=True), axis=2).max(axis=1)
    diag = np.linalg.norm(np.ptp(mesh.points, axis=0))
    d = MESH_KINDS[mesh.kind][1]
    m = np.abs(det).mean(axis=1)
    lo = det.min(axis=1)
    zero = (m <= _ZERO_RTOL * h**d) | (h <= _ZERO_RTOL * diag)
    inverted = ~zero & (lo < -_DEGENERATE_RTOL * m)
    degenerate = ~inverted & (zero | (lo <= _DEGENERATE_RTOL * m))
    problems = []
    if inverted.any():
        order = ("bottom face counter-clockwise seen from +z, then the top face"
                 if mesh.kind == "hex8" else "counter-clockwise seen from +z")
        ids = mesh.element_ids[inverted]
        problems.append(
            f"{ids.size} inverted element(s) (a corner Jacobian determinant <= 0): ids "
            f"{_ids_text(ids)}; is the node order reversed or mirrored? The expected "
            f"{mesh.kind} order is VTK's ({order}); fix it in the mesh generator or export")
    if degenerate.any():
        ids = mesh.element_ids[degenerate]
        problems.append(
            f"{ids.size} degenerate element(s) (zero volume or a corner Jacobian determinant "
            f"near zero): ids {_ids_text(ids)}; duplicate or coincident nodes? Merge "
            "duplicate nodes or remesh")
    if problems:
        raise ValueError(f"{mesh.label}: " + "; ".join(problems))


# --------------------------------------------------------------------------
# generated meshes
# --------------------------------------------------------------------------
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


# --------------------------------------------------------------------------
# reading files
# --------------------------------------------------------------------------
def _gmsh_ids(text: str):
    """Node and element tags of an ASCII MSH 2.2 / 4.1 file, in file order.

    Returns ``(node_tags, element_tags)`` or None (binary or other version).
    """
    lines = [s.strip() for s in text.splitlines()]
    head = lines[lines.index("$MeshFormat") + 1].split()
    if head[1] != "0":
        return None
    version = head[0].split(".")[0]
    i, j = lines.index("$Nodes"), lines.index("$EndNodes")
    k, m = lines.index("$Elements"), lines.index("$EndElements")
    if version == "2":
        nodes = [int(s.split()[0]) for s in lines[i + 2: j]]
        elements = [int(s.split()[0]) for s in lines[k + 2: m]]
    elif head[0] in ("4", "4.1"):
        tok = " ".join(lines[i + 1: j]).split()
        nodes, p = [], 4
        for _ in range(int(tok[0])):    # entityDim entityTag parametric numNodes
            nb = int(tok[p + 3])
            nodes += [int(t) for t in tok[p + 4: p + 4 + nb]]
            p += 4 + 4 * nb             # the tags, then x y z per node
        elements, q = [], k + 2
        while q < m:                    # entityDim entityTag type numElements
            nb = int(lines[q].split()[3])
            elements += [int(s.split()[0]) for s in lines[q + 1: q + 1 + nb]]
            q += 1 + nb
    else:
        return None
    return np.array(nodes, dtype=np.int64), np.array(elements, dtype=np.int64)


def _abaqus_scan(text: str, label: str) -> dict:
    """A pass over an Abaqus file that refuses what meshio 5.3 would misread
    and records what it drops.

    Returns a dict: ``nodes`` node ids in meshio's order, ``blocks`` the
    integers of each ``*ELEMENT`` block (both None if a data line does not
    parse; meshio then reports the file), ``elset_of_block`` each
    ``*ELEMENT`` block's ``ELSET=`` value, ``elsets`` the names ``*ELSET``
    defines.
    """
    nodes, blocks, params, elsets = [], [], [], set()
    mode, name, n_node_blocks, ok = None, None, 0, True
    for line in text.splitlines():
        s = line.strip()
        if line.startswith("*"):
            words = s.split(",")
            mode = None if s.startswith("**") else words[0].replace("*", "").strip().upper()
            opts = {k.strip().upper(): v.strip()
                    for k, _, v in (w.partition("=") for w in words[1:])}
            if mode == "NODE":
                n_node_blocks += 1
                nodes = []
            elif mode == "ELEMENT":
                blocks.append([])
                params.append(opts.get("ELSET"))
            elif mode in ("NSET", "ELSET"):
                name = opts.get(mode)
                if mode == "ELSET":
                    elsets.add(name)
            continue
        if not s or mode is None:
            continue
        first = s.split(",")[0]
        if mode in ("NSET", "ELSET") and not first.isnumeric():
            raise ValueError(f"{label}: *{mode} {name} lists a set by name ({first}); the "
                             "reader (meshio) does not resolve set names, so list the ids instead")
        try:
            if mode == "NODE":
                nodes.append(int(first))
            elif mode == "ELEMENT":
                blocks[-1] += [int(v) for v in s.split(",") if v.strip()]
        except ValueError:
            ok = False
    if n_node_blocks > 1:
        raise ValueError(f"{label}: {n_node_blocks} *NODE blocks; the reader (meshio) keeps "
                         "only the last one, so merge all nodes into a single *NODE block")
    return {"nodes": np.array(nodes, dtype=np.int64) if ok else None,
            "blocks": blocks if ok else None, "elset_of_block": params, "elsets": elsets}


def _file_ids(text: str, raw, abaqus: dict | None):
    """(node_ids, element_ids over all meshio blocks) or None if not recoverable."""
    sizes = [len(b) for b in raw.cells]
    if abaqus is None:
        ids = _gmsh_ids(text)
        if ids is None:
            return None
        nodes, elements = ids
    else:
        nodes, blocks = abaqus["nodes"], abaqus["blocks"]
        if blocks is None or len(blocks) != len(raw.cells):
            return None
        parts = []
        for ints, b in zip(blocks, raw.cells):
            stride = b.data.shape[1] + 1
            if len(ints) != len(b) * stride:
                return None
            parts.append(np.array(ints[::stride], dtype=np.int64))
        elements = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    if nodes.size != len(raw.points) or elements.size != sum(sizes):
        return None
    return nodes, elements


def _plain(v):
    """A numpy scalar as a plain Python value (for messages)."""
    return v.item() if isinstance(v, np.generic) else v


def _holdings(raw) -> str:
    counts: dict[str, int] = {}
    for b in raw.cells:
        counts[b.type] = counts.get(b.type, 0) + len(b)
    return ", ".join(f"{n} {t}" for t, n in counts.items()) or "no cells"


def _choose_kind(raw, dim: int, kind, label: str) -> str:
    allowed = _KINDS_IN[dim]
    supported = ", ".join(f"{TO_MESHIO[k]} ({k})" for k in allowed)
    present = {}
    for b in raw.cells:
        k = _FROM_MESHIO.get(b.type)
        if k in allowed and len(b):
            present[k] = present.get(k, 0) + len(b)
    if kind is not None:
        if kind not in allowed:
            raise ValueError(f"{label}: kind must be one of {list(allowed)} in {dim}D, "
                             f"got {kind!r}")
        if kind not in present:
            raise ValueError(f"{label}: no {TO_MESHIO[kind]} ({kind}) elements; the file holds "
                             f"{_holdings(raw)}")
        return kind
    if not present:
        raise ValueError(f"{label}: no elements of a supported kind in {dim}D ({supported}); "
                         f"the file holds {_holdings(raw)}; mesh with those element types "
                         "(linear, all-hexahedral or all-quad meshes)")
    if len(present) > 1:
        listing = ", ".join(f"{n} {k}" for k, n in present.items())
        raise ValueError(f"{label}: several supported element kinds ({listing}); say which one "
                         f"to read with kind= (one of {list(present)}); the groups of the "
                         "others become node sets")
    return next(iter(present))


def _groups(raw, label: str) -> dict[str, list[np.ndarray]]:
    """Named groups as per-block local element indices (meshio cell_sets, or
    Gmsh physical tags + names)."""
    nb = len(raw.cells)
    groups = {}
    for name, per_block in (raw.cell_sets or {}).items():
        if name.startswith("gmsh:"):
            continue
        arrays = [np.zeros(0, np.int64)] * nb
        try:
            for b, a in enumerate(list(per_block)[:nb]):
                if a is not None:
                    arrays[b] = np.asarray(a, dtype=np.int64).reshape(-1)
        except (TypeError, ValueError):
            raise ValueError(f"{label}: set {name!r} could not be interpreted; list its element "
                             "ids explicitly") from None
        groups[name] = arrays
    physical = (raw.cell_data or {}).get("gmsh:physical")
    if physical is not None:
        for name, (tag, gdim) in ((k, v[:2]) for k, v in (raw.field_data or {}).items()):
            if name not in groups:
                groups[name] = [np.flatnonzero(np.asarray(t) == tag) if b.dim == gdim
                                else np.zeros(0, np.int64)
                                for b, t in zip(raw.cells, physical)]
    return groups


def _merge_repeats(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elements with the same nodes, kept once.

    Returns ``order`` (the rows kept, first occurrences in file order) and
    ``elem_map`` (E,): old row -> index into ``order``.
    """
    _, first, inverse = np.unique(np.sort(cells, axis=1), axis=0, return_index=True,
                                  return_inverse=True)
    rank = np.empty(first.size, np.int64)
    rank[np.argsort(first)] = np.arange(first.size)
    return np.sort(first), rank[inverse.reshape(-1)]


def read_mesh(path, dim: int, kind: str | None = None) -> MeshData:
    """Read a finite-element mesh from a Gmsh ``.msh`` or Abaqus ``.inp`` file.

    Gmsh MSH 2.2 and 4.1 (ASCII or binary) and Abaqus input files are read
    with meshio's readers. Both formats (and meshio) store the linear
    hexahedron, quadrilateral and line in VTK node order, so the connectivity
    is used as is; in 2D, quads numbered clockwise (a surface whose normal is
    -z) are renumbered counter-clockwise, so that every valid element has
    positive Jacobians. Call :func:`check_elements` on the result to refuse
    inverted or degenerate elements.

    Parameters
    ----------
    path : str or path-like
        The mesh file; its extension (``.msh``, ``.inp``) selects the format.
    dim : {2, 3}
        Spatial dimension. In 2D all nodes must lie in one plane z = const
        (to ``1e-6`` times the x-y extent); the mesh is projected to z = 0.
    kind : {"hex8", "line2"} in 3D, {"quad4", "line2"} in 2D, optional
        Which elements to keep (meshio types hexahedron, quad, line). By
        default the single supported kind present; with several present the
        caller must choose.

    Returns
    -------
    MeshData
        The kept elements and only the nodes they use (renumbered 0..N-1 in
        file order). ``node_ids`` / ``element_ids`` are the file's node and
        element numbers (Gmsh tags, Abaqus ids) for ASCII files; for binary
        Gmsh files, or Abaqus files with ``*INCLUDE``, the 1-based positions
        in the file. Sets:

        * every named group (Gmsh physical group with a name in
          ``$PhysicalNames``; Abaqus ``ELSET``) with elements of the kept
          kind becomes an element set, and the node set of its nodes under
          the same name;
        * groups of other element types (e.g. Gmsh physical surfaces of a hex
          mesh, which mark boundary faces) become node sets of their nodes;
        * Abaqus ``NSET`` become node sets (taking precedence over a node set
          derived from an element group of the same name);
        * ``"all"`` (element and node set), unless the file defines it.

        Node sets hold only nodes of the kept elements; sets left empty are
        dropped. Elements listed twice with the same nodes (MSH 2.2 repeats
        an element for each physical group it belongs to) are kept once,
        in all their groups.

    Raises
    ------
    ValueError
        Missing or unreadable file, unsupported extension, no elements of a
        supported kind, several kinds and no ``kind``, a non-planar 2D mesh.
    """
    dim = _check_dim(dim)
    path = Path(path)
    label = f"mesh file '{path}'"
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"{label}: unsupported extension {path.suffix!r}; use a Gmsh .msh "
                         "or an Abaqus .inp file")
    if not path.is_file():
        raise ValueError(f"{label}: no such file; check the path (relative paths are "
                         "relative to the deck)")
    fmt, fmt_label, reader = fmt
    text = path.read_bytes().decode("latin-1")
    abaqus = _abaqus_scan(text, label) if fmt == "abaqus" else None
    try:
        raw = reader(path)
    except Exception as exc:  # meshio raises ReadError, ValueError, KeyError, ...
        if isinstance(exc, KeyError) and exc.args:
            detail = f"id {_plain(exc.args[0])} is used but not defined"
        else:
            detail = type(exc).__name__ + (f": {exc}" if str(exc) else "")
        want = ("a complete Gmsh MSH 2.2 or 4.1 file" if fmt == "gmsh" else
                "a complete Abaqus input file (*NODE before *ELEMENT, every node defined)")
        raise ValueError(f"{label}: cannot read it as {fmt_label} mesh ({detail}); check "
                         f"that it is {want}") from exc
    kind = _choose_kind(raw, dim, kind, label)

    try:
        ids = _file_ids(text, raw, abaqus)
    except (ValueError, IndexError):
        ids = None
    n_raw = len(raw.points)
    if ids is None:
        ids = (np.arange(1, n_raw + 1), np.arange(1, sum(len(b) for b in raw.cells) + 1))
    starts = np.cumsum([0] + [len(b) for b in raw.cells])
    points = np.zeros((n_raw, 3))
    raw_points = np.asarray(raw.points, dtype=np.float64).reshape(n_raw, -1)
    points[:, :raw_points.shape[1]] = raw_points[:, :3]

    keep = [b for b, blk in enumerate(raw.cells) if _FROM_MESHIO.get(blk.type) == kind]
    cells = np.concatenate([np.asarray(raw.cells[b].data, dtype=np.int64) for b in keep])
    element_ids = np.concatenate([ids[1][starts[b]:starts[b + 1]] for b in keep])

    order, elem_map = _merge_repeats(cells)
    cells, element_ids = cells[order], element_ids[order]

    # drop unused nodes, renumber in file order
    used = np.unique(cells)
    node_map = np.full(n_raw, -1, np.int64)
    node_map[used] = np.arange(used.size)
    cells = node_map[cells]
    points, node_ids = points[used], ids[0][used]

    if dim == 2:
        z = points[:, 2]
        tol = 1e-6 * max(np.ptp(points[:, 0]), np.ptp(points[:, 1]), np.finfo(float).tiny)
        z_mid = np.median(z)
        worst = int(np.argmax(np.abs(z - z_mid)))
        if abs(z[worst] - z_mid) > tol:
            raise ValueError(f"{label}: a 2D mesh must lie in a plane z = const, but node "
                             f"{node_ids[worst]} has z = {z[worst]:.6g} (median {z_mid:.6g}); "
                             "mesh in the x-y plane or read it with dim=3")
        points[:, 2] = 0.0
        if kind == "quad4":
            clockwise = np.all(element_jacobians(points, cells, kind) < 0.0, axis=1)
            cells[clockwise] = cells[clockwise][:, [0, 3, 2, 1]]

    groups = _groups(raw, label)
    if abaqus is not None and len(abaqus["elset_of_block"]) == len(raw.cells):
        # meshio files *ELEMENT, ELSET=name under the wrong block when some
        # *ELEMENT blocks have no ELSET; rebuild those sets from the blocks
        params = abaqus["elset_of_block"]
        for name in set(filter(None, params)) - abaqus["elsets"]:
            groups[name] = [np.arange(len(b)) if p == name else np.zeros(0, np.int64)
                            for p, b in zip(params, raw.cells)]
    # element indices: block b's local element i is old element offset[b] + i
    offset = dict(zip(keep, np.cumsum([0] + [len(raw.cells[b]) for b in keep])))
    element_sets, node_sets = {}, {}
    for name, local in groups.items():
        try:
            members = [elem_map[offset[b] + local[b]] for b in keep if local[b].size]
            nodes = [np.asarray(raw.cells[b].data, dtype=np.int64)[a].reshape(-1)
                     for b, a in enumerate(local) if a.size]
        except IndexError:
            raise ValueError(f"{label}: group {name!r} refers to elements that do not "
                             "exist; check the file's sets") from None
        if members:
            element_sets[name] = np.concatenate(members)
        nodes = node_map[np.concatenate(nodes)] if nodes else np.zeros(0, np.int64)
        if np.any(nodes >= 0):
            node_sets[name] = nodes[nodes >= 0]
    for name, idx in (raw.point_sets or {}).items():
        nodes = node_map[np.asarray(idx, dtype=np.int64).reshape(-1)]
        if np.any(nodes >= 0):
            node_sets[name] = nodes[nodes >= 0]
        else:
            node_sets.pop(name, None)
    element_sets.setdefault("all", np.arange(cells.shape[0]))
    node_sets.setdefault("all", np.arange(points.shape[0]))
    return MeshData(points, cells, kind, node_sets=node_sets, element_sets=element_sets,
                    element_ids=element_ids, node_ids=node_ids, source=f"file '{path}'")
