"""ParaView output: particle clouds as ``.vtu`` files and ``.pvd`` time series.

Particles are written as a VTK UnstructuredGrid with one ``VTK_VERTEX`` cell
per particle (so ParaView filters that need cells work directly), in binary
through :mod:`meshio` (uncompressed by default: zlib is about 10 times slower to
write for a 20 % smaller file of particle data). Point data:

* scalars ``(N,)`` -> 1 component,
* vectors ``(N, 3)`` -> 3 components,
* tensors ``(N, 3, 3)`` or ``(N, 9)`` -> 9 components, row-major
  (xx, xy, xz, yx, ..., zz), which ParaView recognises as a tensor.

Integer arrays are kept as integers, booleans are written as ``uint8``.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

from .atomic import atomic_path, atomic_write_text

__all__ = ["write_vtu", "write_pvd", "read_pvd"]

# dtypes the VTU format (and meshio) can store directly.
_VTU_DTYPES = {np.dtype(t) for t in (np.float32, np.float64, np.int8, np.int16,
                                     np.int32, np.int64, np.uint8, np.uint16,
                                     np.uint32, np.uint64)}


def _point_array(name: str, data: np.ndarray, n: int) -> np.ndarray:
    """Shape and dtype of one point-data array as VTU wants it."""
    data = np.asarray(data)
    if data.ndim == 0 or data.shape[0] != n:
        raise ValueError(f"point data {name!r} has shape {data.shape}, "
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
            raise TypeError(f"point data {name!r}: unsupported dtype {data.dtype}")
    return np.ascontiguousarray(data)


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
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"positions must have shape (N, 3), got {x.shape}")
    if x.shape[1] == 2:
        x = np.column_stack([x, np.zeros(len(x))])
    n = len(x)
    data = {name: _point_array(name, arr, n) for name, arr in point_data.items()}
    cells = [meshio.CellBlock("vertex", np.arange(n, dtype=np.int64).reshape(n, 1))]
    mesh = meshio.Mesh(np.ascontiguousarray(x), cells, point_data=data)
    path = Path(path)
    with atomic_path(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu", binary=True,
                     compression="zlib" if compress else None)
    return path


def write_pvd(path: str | os.PathLike, entries: list[tuple[float, str]]) -> Path:
    """Write a ParaView collection (``.pvd``) listing a time series of datasets.

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.pvd`` file (replaced atomically if it exists).
    entries : list of (float, str)
        ``(time [s], file)`` pairs in output order. Files are stored relative
        to the directory of ``path`` (absolute paths are made relative), with
        forward slashes.

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
    for t, file in entries:
        file = Path(file)
        if file.is_absolute():
            file = Path(os.path.relpath(file, base))
        ET.SubElement(collection, "DataSet", timestep=repr(float(t)), group="",
                      part="0", file=file.as_posix())
    ET.indent(root)
    text = '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    atomic_write_text(path, text)
    return path


def read_pvd(path: str | os.PathLike) -> list[tuple[float, str]]:
    """Read the ``(time, file)`` entries of a ``.pvd`` collection.

    Files are returned as stored (relative to the ``.pvd`` directory).
    """
    root = ET.parse(path).getroot()
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise ValueError(f"{path} is not a VTK collection file")
    return [(float(ds.get("timestep", "0")), ds.get("file", ""))
            for ds in root.iter("DataSet")]
