"""Finite-element meshes of a frame: :class:`MeshFrame` and the element kinds.

A frame holds the particle fields and, beside them, any number of named mesh
blocks (one per finite-element part). A block is the current geometry of the
part and its fields at the frame's time:

* ``points (N, 3)``: node positions [m] (``(N, 2)`` is accepted and padded
  with ``z = 0`` when written to VTK),
* ``cells (E, nen)``: node indices of each element, in VTK node order,
* ``kind``: one of :data:`MESH_KINDS` (``"hex8"``, ``"quad4"``, ``"line2"``),
* ``point_data``: node fields, arrays ``(N,)``, ``(N, k)`` or ``(N, 3, 3)``,
* ``cell_data``: element fields, arrays ``(E,)``, ``(E, k)`` or ``(E, 3, 3)``.

The same object is written to the HDF5 frame (:mod:`sphdyn.io.hdf5`), to a
``.vtu`` file (:func:`sphdyn.io.vtk.write_mesh_vtu`) and read back by
:func:`sphdyn.io.hdf5.read_frame_meshes`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..geometry.mesh import MESH_KINDS as GEOMETRY_KINDS
from ..geometry.mesh import TO_MESHIO

__all__ = ["MeshFrame", "MESH_KINDS", "check_mesh_name"]

#: Element kind -> (nodes per element, meshio cell type = VTK cell), from the
#: mesh module's tables
MESH_KINDS: dict[str, tuple[int, str]] = {k: (nen, TO_MESHIO[k])
                                          for k, (nen, _) in GEOMETRY_KINDS.items()}

#: Block name of the particles in a ``.pvd`` collection; no mesh may use it.
PARTICLES_BLOCK = "particles"

# Mesh names become HDF5 group names and directory names (vtk/<name>/).
_NAME_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")


def check_mesh_name(name: str) -> None:
    """Raise :class:`ValueError` unless ``name`` can name a mesh block.

    Allowed: letters, digits, ``_``, ``.``, ``-``, not starting with ``.`` or
    ``-`` (the name is used as an HDF5 group and as a directory name), and not
    ``"particles"`` (the block name of the particles).
    """
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise ValueError(f"invalid mesh name {name!r}: use letters, digits, '_', '.' "
                         "and '-', starting with a letter, digit or '_'")
    if name == PARTICLES_BLOCK:
        raise ValueError(f"mesh name {name!r} is reserved for the particle block")


def _check_fields(data: dict[str, np.ndarray], n: int, what: str) -> dict[str, np.ndarray]:
    """``data`` as arrays, each with first dimension ``n``."""
    out = {}
    for name, arr in data.items():
        if not isinstance(name, str) or not name or "/" in name:
            raise ValueError(f"invalid {what} name {name!r} (non-empty, no '/')")
        arr = np.asarray(arr)
        if arr.ndim == 0 or arr.shape[0] != n:
            raise ValueError(f"{what} {name!r} has shape {arr.shape}, "
                             f"expected first dimension {n}")
        out[name] = arr
    return out


@dataclass
class MeshFrame:
    """One mesh block of a frame (see the module docstring for the shapes).

    Attributes
    ----------
    points : (N, 3) ndarray
        Node positions [m] at the frame time (``(N, 2)`` allowed in 2D).
    cells : (E, nen) ndarray of int
        Connectivity in VTK node order, indices into ``points``.
    kind : str
        ``"hex8"`` (nen 8), ``"quad4"`` (nen 4) or ``"line2"`` (nen 2).
    point_data : dict of str to ndarray
        Node fields (displacement [m], velocity [m/s], ...), first dimension N.
    cell_data : dict of str to ndarray
        Element fields (stress [Pa] as ``(E, 3, 3)``, damage, ...), first
        dimension E.

    Raises
    ------
    ValueError
        On an unknown kind, a connectivity of the wrong width or out of range,
        or a field whose first dimension does not match.
    """

    points: np.ndarray
    cells: np.ndarray
    kind: str
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in MESH_KINDS:
            raise ValueError(f"mesh kind must be one of {tuple(MESH_KINDS)}, "
                             f"got {self.kind!r}")
        nen = MESH_KINDS[self.kind][0]
        self.points = np.asarray(self.points)
        if self.points.ndim != 2 or self.points.shape[1] not in (2, 3):
            raise ValueError(f"mesh points must have shape (N, 3), got {self.points.shape}")
        self.cells = np.asarray(self.cells)
        if self.cells.ndim != 2 or self.cells.shape[1] != nen:
            raise ValueError(f"{self.kind} cells must have shape (E, {nen}), "
                             f"got {self.cells.shape}")
        if self.cells.size and self.cells.dtype.kind not in "iu":
            raise TypeError(f"mesh cells must be integers, got {self.cells.dtype}")
        n = len(self.points)
        if self.cells.size and (self.cells.min() < 0 or self.cells.max() >= n):
            raise ValueError(f"mesh cells refer to nodes outside 0..{n - 1}")
        self.point_data = _check_fields(self.point_data, n, "point data")
        self.cell_data = _check_fields(self.cell_data, len(self.cells), "cell data")

    @property
    def n_points(self) -> int:
        """Number of nodes N."""
        return len(self.points)

    @property
    def n_cells(self) -> int:
        """Number of elements E."""
        return len(self.cells)
