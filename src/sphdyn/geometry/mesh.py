"""Finite-element meshes: the :class:`MeshData` every mesh is, its element kinds
and node order, and the checks of its elements.

A mesh is a :class:`MeshData`: node positions ``points`` (N, 3) float64 in
metres (2D = plane strain in the x-y plane, ``z = 0``), connectivity
``cells`` (E, nen) int64 of 0-based node indices, one element kind per mesh,
and named node and element sets. Generated meshes (boxes, graded boxes,
prisms, lines): :mod:`sphdyn.geometry.mesh_blocks`; meshes read from Gmsh and
Abaqus files: :mod:`sphdyn.geometry.mesh_files`.

Element kinds and node order (VTK's, which is also LS-DYNA's, Gmsh's and
Abaqus's for these linear elements, and meshio's):

* ``"hex8"`` (3D): nodes 0-3 on the bottom face (zeta = -1) counter-clockwise
  seen from +z, at natural coordinates (-,-,-), (+,-,-), (+,+,-), (-,+,-);
  nodes 4-7 the same on the top face (zeta = +1);
* ``"quad4"`` (2D): (-,-), (+,-), (+,+), (-,+), counter-clockwise;
* ``"line2"`` (beams, trusses; 2D or 3D): start, end.

In this order a right-handed (undistorted) element has a positive Jacobian
determinant at every corner (:func:`element_jacobians`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
import numpy as np

from .shapes import corner_signs, shape_derivatives

__all__ = ["MESH_KINDS", "MeshData", "TO_MESHIO", "check_elements", "element_jacobians"]

#: element kind -> (nodes per element, topological dimension)
MESH_KINDS = {"hex8": (8, 3), "quad4": (4, 2), "line2": (2, 1)}

# kinds a mesh of spatial dimension dim may hold
_KINDS_IN = {2: ("quad4", "line2"), 3: ("hex8", "line2")}
# meshio cell type <-> kind
#: element kind <-> meshio cell type (= the VTK cell: hexahedron 12, quad 9, line 3)
TO_MESHIO = {"hex8": "hexahedron", "quad4": "quad", "line2": "line"}
_FROM_MESHIO = {v: k for k, v in TO_MESHIO.items()}

# Thresholds of check_elements (relative, see its docstring).
_DEGENERATE_RTOL = 1e-6
_ZERO_RTOL = 1e-12
_MAX_IDS = 10


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
