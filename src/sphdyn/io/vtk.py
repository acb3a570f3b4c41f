"""ParaView output: particles and meshes as ``.vtu`` files, ``.pvd`` time series.

Particles are written as a VTK UnstructuredGrid with one ``VTK_VERTEX`` cell
per particle (so ParaView filters that need cells work directly), finite-element
meshes (:func:`write_mesh_vtu`) as an UnstructuredGrid of hexahedra, quads or
lines, both in binary through :mod:`meshio` (uncompressed by default: zlib is
about 10 times slower to write for a 20 % smaller file of particle data).
Point (and cell) data:

* scalars ``(N,)`` -> 1 component,
* vectors ``(N, 3)`` -> 3 components,
* tensors ``(N, 3, 3)`` or ``(N, 9)`` -> 9 components, row-major
  (xx, xy, xz, yx, ..., zz), which ParaView recognises as a tensor.

Integer arrays are kept as integers, booleans are written as ``uint8``.

A ``.pvd`` collection lists ``<DataSet timestep=... part=... file=.../>``
entries. ParaView's PVD reader takes the distinct ``timestep`` strings as the
time steps and, at each of them, reads every entry of that time step: one
entry gives that dataset, several give a multiblock dataset with one block per
entry, in file order, named by the entry's ``name`` attribute. Particles and
the mesh parts of a run are therefore listed as several entries per time step
(:class:`PvdDataSet`), with the same ``part`` number and ``name`` for a block
at every time step (``part`` also lets VTK's collection reader select one
block's series with a restriction). The kind of output (single dataset or
multiblock) is fixed by the first time step, so a run lists the same blocks
at every time step.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np

from .atomic import atomic_path, atomic_write_text
from .meshes import MESH_KINDS

__all__ = ["write_vtu", "write_mesh_vtu", "write_pvd", "read_pvd", "read_pvd_datasets",
           "PvdDataSet"]

# dtypes the VTU format (and meshio) can store directly.
_VTU_DTYPES = {np.dtype(t) for t in (np.float32, np.float64, np.int8, np.int16,
                                     np.int32, np.int64, np.uint8, np.uint16,
                                     np.uint32, np.uint64)}


def _vtu_array(name: str, data: np.ndarray, n: int, what: str = "point data"
               ) -> np.ndarray:
    """Shape and dtype of one point- or cell-data array as VTU wants it.

    ``(n,)`` and ``(n, k)`` arrays are kept, ``(n, 3, 3)`` tensors become
    ``(n, 9)`` row-major; booleans become ``uint8``, other dtypes the nearest
    one VTU stores.
    """
    data = np.asarray(data)
    if data.ndim == 0 or data.shape[0] != n:
        raise ValueError(f"{what} {name!r} has shape {data.shape}, "
                         f"expected first dimension {n}")
    if data.ndim > 2:
        data = data.reshape(n, -1)  # (N, 3, 3) -> (N, 9), row-major
    if data.dtype == np.bool_:
        data = data.astype(np.uint8)
    elif data.dtype not in _VTU_DTYPES:
        if data.dtype.kind == "f":
            data = data.astype(np.float64)
        elif data.dtype.kind in "iu":
            data = data.astype(np.int64)
        else:
            raise TypeError(f"{what} {name!r}: unsupported dtype {data.dtype}")
    return np.ascontiguousarray(data)


def _vtu_arrays(data: dict[str, np.ndarray], n: int, what: str
                ) -> dict[str, np.ndarray]:
    """:func:`_vtu_array` applied to every array of ``data``."""
    return {name: _vtu_array(name, arr, n, what) for name, arr in data.items()}


def _points3(x: np.ndarray, what: str = "positions") -> np.ndarray:
    """``(N, 3)`` float64 positions [m]; ``(N, 2)`` is padded with ``z = 0``."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"{what} must have shape (N, 3), got {x.shape}")
    if x.shape[1] == 2:
        x = np.column_stack([x, np.zeros(len(x))])
    return np.ascontiguousarray(x)


def _write_grid(path: str | os.PathLike, mesh: meshio.Mesh, compress: bool) -> Path:
    """Write ``mesh`` as a binary ``.vtu`` file, atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu", binary=True,
                     compression="zlib" if compress else None)
    return path


def write_vtu(path: str | os.PathLike, x: np.ndarray,
              point_data: dict[str, np.ndarray], compress: bool = False) -> Path:
    """Write particles as a binary VTK UnstructuredGrid of vertex cells (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.vtu`` file (replaced if it exists).
    x : (N, 3) ndarray
        Particle positions [m]; ``(N, 2)`` is padded with ``z = 0``.
    point_data : dict of str to ndarray
        Arrays of shape ``(N,)``, ``(N, k)`` or ``(N, 3, 3)`` (written with
        9 components).
    compress : bool, optional
        zlib-compress the data arrays (smaller, much slower to write).

    Returns
    -------
    pathlib.Path
        The path written.
    """
    x = _points3(x)
    n = len(x)
    data = _vtu_arrays(point_data, n, "point data")
    cells = [meshio.CellBlock("vertex", np.arange(n, dtype=np.int64).reshape(n, 1))]
    return _write_grid(path, meshio.Mesh(x, cells, point_data=data), compress)


def write_mesh_vtu(path: str | os.PathLike, points: np.ndarray, cells: np.ndarray,
                   kind: str, point_data: dict[str, np.ndarray] | None = None,
                   cell_data: dict[str, np.ndarray] | None = None,
                   compress: bool = False) -> Path:
    """Write a finite-element mesh as a binary VTK UnstructuredGrid (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.vtu`` file (replaced if it exists).
    points : (N, 3) ndarray
        Node positions [m]; ``(N, 2)`` is padded with ``z = 0``.
    cells : (E, nen) ndarray of int
        Connectivity in VTK node order (indices into ``points``).
    kind : str
        ``"hex8"`` (VTK hexahedron), ``"quad4"`` (VTK quad) or ``"line2"``
        (VTK line); see :data:`sphdyn.io.meshes.MESH_KINDS`.
    point_data : dict of str to ndarray, optional
        Node fields ``(N,)``, ``(N, k)`` or ``(N, 3, 3)`` (displacement [m],
        velocity [m/s], ...).
    cell_data : dict of str to ndarray, optional
        Element fields ``(E,)``, ``(E, k)`` or ``(E, 3, 3)`` (stress [Pa],
        damage, ...); tensors get 9 components, row-major, as for particles.
    compress : bool, optional
        zlib-compress the data arrays.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    if kind not in MESH_KINDS:
        raise ValueError(f"mesh kind must be one of {tuple(MESH_KINDS)}, got {kind!r}")
    nen, cell_type = MESH_KINDS[kind]
    x = _points3(points, "mesh points")
    conn = np.asarray(cells)
    if conn.ndim != 2 or conn.shape[1] != nen:
        raise ValueError(f"{kind} cells must have shape (E, {nen}), got {conn.shape}")
    if conn.size and (conn.min() < 0 or conn.max() >= len(x)):
        raise ValueError(f"mesh cells refer to nodes outside 0..{len(x) - 1}")
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    p_data = _vtu_arrays(point_data or {}, len(x), "point data")
    c_data = {name: [arr] for name, arr in
              _vtu_arrays(cell_data or {}, len(conn), "cell data").items()}
    mesh = meshio.Mesh(x, [meshio.CellBlock(cell_type, conn)], point_data=p_data,
                       cell_data=c_data)
    return _write_grid(path, mesh, compress)


@dataclass(frozen=True)
class PvdDataSet:
    """One ``<DataSet>`` entry of a ``.pvd`` collection.

    Attributes
    ----------
    time : float
        Time [s] (the ``timestep`` attribute).
    file : str
        Dataset file, relative to the ``.pvd`` directory.
    part : int
        Block number within the time step (the same for a block at every
        time step); 0 for single-block collections.
    name : str or None
        Block name shown by ParaView (``"particles"`` or the mesh name);
        None when the entry has no ``name`` attribute (single-block files).
    """

    time: float
    file: str
    part: int = 0
    name: str | None = None


def write_pvd(path: str | os.PathLike,
              entries: list[tuple[float, str] | PvdDataSet]) -> Path:
    """Write a ParaView collection (``.pvd``) listing a time series of datasets.

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.pvd`` file (replaced atomically if it exists).
    entries : list of (float, str) or PvdDataSet
        In output order. A ``(time [s], file)`` pair is a single-block entry
        (``part="0"``, no name); a :class:`PvdDataSet` also gives the block's
        part number and name, for several blocks per time step (list them with
        the same ``time``). Files are stored relative to the directory of
        ``path`` (absolute paths are made relative), with forward slashes.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    path = Path(path)
    root = ET.Element("VTKFile", type="Collection", version="0.1",
                      byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    base = path.parent.resolve()
    for entry in entries:
        if not isinstance(entry, PvdDataSet):
            entry = PvdDataSet(*entry)
        file = Path(entry.file)
        if file.is_absolute():
            file = Path(os.path.relpath(file, base))
        attrs = {"timestep": repr(float(entry.time)), "group": "",
                 "part": str(int(entry.part))}
        if entry.name is not None:
            attrs["name"] = entry.name
        attrs["file"] = file.as_posix()
        ET.SubElement(collection, "DataSet", attrs)
    ET.indent(root)
    text = '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    atomic_write_text(path, text)
    return path


def read_pvd_datasets(path: str | os.PathLike) -> list[PvdDataSet]:
    """Read every ``<DataSet>`` entry of a ``.pvd`` collection, in file order.

    Works for single-block files (``part`` 0, ``name`` None) and for
    multi-block ones. Files are returned as stored (relative to the ``.pvd``
    directory).
    """
    root = ET.parse(path).getroot()
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise ValueError(f"{path} is not a VTK collection file")
    return [PvdDataSet(float(ds.get("timestep", "0")), ds.get("file", ""),
                       int(ds.get("part", "0") or 0), ds.get("name"))
            for ds in root.iter("DataSet")]


def read_pvd(path: str | os.PathLike) -> list[tuple[float, str]]:
    """Read the ``(time, file)`` entries of a ``.pvd`` collection.

    Files are returned as stored (relative to the ``.pvd`` directory). A
    multi-block collection gives one pair per block and time step (times
    repeat); :func:`read_pvd_datasets` also gives the parts and names.
    """
    return [(ds.time, ds.file) for ds in read_pvd_datasets(path)]
