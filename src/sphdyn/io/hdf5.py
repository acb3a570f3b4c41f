"""Native HDF5 output: one file per particle frame, and restart checkpoints.

Frame file layout (``write_frame``)::

    /                attrs: sphdyn_format="frame", format_version, time, step, <attrs>
    /<field name>    one dataset per field, dtype and shape as given
    /meshes/<name>   optional mesh blocks (see sphdyn.io.meshes), each with
                     attrs: kind ("hex8", "quad4", "line2")
                     points (N, 3), cells (E, nen), point_data/<f>, cell_data/<f>

A frame without meshes has no ``meshes`` group (the layout of particle-only
frames is unchanged); every frame holds its own connectivity, so a frame file
is readable alone.

Checkpoint file layout (``write_checkpoint``)::

    /                attrs: sphdyn_format="checkpoint", format_version
    /arrays/<name>   datasets
    /scalars         attrs: one per scalar (float, int, str or bool)
    /groups/<g>/<n>  datasets of the named sub-dictionaries

HDF5 stores numbers in their binary form, so a checkpoint round trip is
bitwise exact (dtype, shape and every bit of every value, NaNs included).
All files are written through :func:`sphdyn.io.atomic.atomic_path`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .atomic import atomic_path
from .meshes import MeshFrame, check_mesh_name

__all__ = [
    "write_frame", "read_frame", "read_frame_header", "read_frame_meshes",
    "read_frame_mesh_names",
    "write_checkpoint", "read_checkpoint",
]

FORMAT_VERSION = 1
_RESERVED_FRAME_ATTRS = ("sphdyn_format", "format_version", "time", "step")
MESHES_GROUP = "meshes"


def _check_name(name: str, what: str) -> None:
    if not isinstance(name, str) or not name or "/" in name or name in (".", ".."):
        raise ValueError(f"invalid {what} name {name!r} (non-empty, no '/')")


def _to_python(value: Any) -> Any:
    """HDF5 attribute value -> plain Python scalar where possible."""
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def _check_format(f: h5py.File, expected: str, path: Path) -> None:
    fmt = _to_python(f.attrs.get("sphdyn_format", ""))
    if fmt != expected:
        raise ValueError(f"{path} is not an sphdyn {expected} file "
                         f"(sphdyn_format={fmt!r})")


# --------------------------------------------------------------------------- frames

def _write_mesh(group: h5py.Group, mesh: MeshFrame) -> None:
    """Store one mesh block in ``group`` (see the module docstring)."""
    group.attrs["kind"] = mesh.kind
    group.create_dataset("points", data=mesh.points)
    group.create_dataset("cells", data=mesh.cells)
    for sub, data in (("point_data", mesh.point_data), ("cell_data", mesh.cell_data)):
        g = group.create_group(sub, track_order=True)
        for name, arr in data.items():
            g.create_dataset(name, data=arr)


def _read_mesh(group: h5py.Group) -> MeshFrame:
    """Inverse of :func:`_write_mesh`."""
    return MeshFrame(points=group["points"][()], cells=group["cells"][()],
                     kind=_to_python(group.attrs["kind"]),
                     point_data={k: v[()] for k, v in group["point_data"].items()},
                     cell_data={k: v[()] for k, v in group["cell_data"].items()})


def write_frame(path: str | os.PathLike, t: float, step: int,
                fields: dict[str, np.ndarray],
                attrs: dict[str, Any] | None = None,
                meshes: dict[str, MeshFrame] | None = None) -> Path:
    """Write one frame (particles, optional mesh blocks) to its own HDF5 file (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.h5`` file (replaced if it exists).
    t : float
        Simulation time [s], stored as the root attribute ``time``.
    step : int
        Time-step number, stored as the root attribute ``step``.
    fields : dict of str to ndarray
        One dataset per field, written with the dtype and shape given.
    attrs : dict, optional
        Extra root attributes (numbers, strings, small arrays). The names
        ``time``, ``step``, ``sphdyn_format`` and ``format_version`` are
        reserved.
    meshes : dict of str to MeshFrame, optional
        Mesh blocks by name (:func:`sphdyn.io.meshes.check_mesh_name`),
        written under ``/meshes/<name>`` in the order given; none (or an
        empty dict) writes no ``meshes`` group.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    attrs = dict(attrs or {})
    clash = [k for k in attrs if k in _RESERVED_FRAME_ATTRS]
    if clash:
        raise ValueError(f"reserved frame attribute names: {clash}")
    for name in fields:
        _check_name(name, "field")
    meshes = dict(meshes or {})
    if meshes and MESHES_GROUP in fields:
        raise ValueError(f"a frame with meshes cannot have a field named {MESHES_GROUP!r}")
    for name, mesh in meshes.items():
        check_mesh_name(name)
        if not isinstance(mesh, MeshFrame):
            raise TypeError(f"mesh {name!r} must be a MeshFrame, got {type(mesh).__name__}")
    path = Path(path)
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["sphdyn_format"] = "frame"
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["time"] = float(t)
            f.attrs["step"] = int(step)
            for key, value in attrs.items():
                f.attrs[key] = value
            for name, data in fields.items():
                f.create_dataset(name, data=np.asarray(data))
            if meshes:
                g_meshes = f.create_group(MESHES_GROUP, track_order=True)
                for name, mesh in meshes.items():
                    _write_mesh(g_meshes.create_group(name, track_order=True), mesh)
    return path


def read_frame_header(path: str | os.PathLike) -> tuple[float, int, dict[str, Any]]:
    """Read only the time, step and extra attributes of a frame file.

    Returns
    -------
    t : float
    step : int
    attrs : dict
        The extra attributes given to :func:`write_frame`.
    """
    path = Path(path)
    with h5py.File(path, "r") as f:
        _check_format(f, "frame", path)
        t = float(f.attrs["time"])
        step = int(f.attrs["step"])
        attrs = {k: _to_python(v) for k, v in f.attrs.items()
                 if k not in _RESERVED_FRAME_ATTRS}
    return t, step, attrs


def read_frame(path: str | os.PathLike
               ) -> tuple[float, int, dict[str, np.ndarray], dict[str, Any]]:
    """Read a frame written by :func:`write_frame`.

    Returns
    -------
    t : float
        Simulation time [s].
    step : int
        Time-step number.
    fields : dict of str to ndarray
        The datasets, in the order they were written (mesh blocks are not
        among them: see :func:`read_frame_meshes`).
    attrs : dict
        The extra attributes given to :func:`write_frame`.
    """
    path = Path(path)
    t, step, attrs = read_frame_header(path)
    with h5py.File(path, "r") as f:
        # Files are written with track_order=True: iteration is creation order.
        fields = {name: ds[()] for name, ds in f.items()
                  if isinstance(ds, h5py.Dataset)}
    return t, step, fields, attrs


def read_frame_mesh_names(path: str | os.PathLike) -> list[str]:
    """Names of the mesh blocks of a frame file, in the order written ([] if none)."""
    path = Path(path)
    with h5py.File(path, "r") as f:
        _check_format(f, "frame", path)
        group = f.get(MESHES_GROUP)
        return list(group.keys()) if isinstance(group, h5py.Group) else []


def read_frame_meshes(path: str | os.PathLike) -> dict[str, MeshFrame]:
    """Read the mesh blocks of a frame written by :func:`write_frame`.

    Returns
    -------
    dict of str to MeshFrame
        The blocks by name, in the order written; empty for a particle-only
        frame. Arrays have the dtypes and shapes given to :func:`write_frame`.
    """
    path = Path(path)
    with h5py.File(path, "r") as f:
        _check_format(f, "frame", path)
        group = f.get(MESHES_GROUP)
        if not isinstance(group, h5py.Group):
            return {}
        return {name: _read_mesh(g) for name, g in group.items()}


# ---------------------------------------------------------------------- checkpoints

def _write_arrays(group: h5py.Group, arrays: dict[str, np.ndarray], what: str) -> None:
    for name, data in arrays.items():
        _check_name(name, what)
        data = np.asarray(data)
        if data.dtype.kind not in "biufc":
            raise TypeError(f"{what} {name!r}: unsupported dtype {data.dtype} "
                            "(only bool, integer, float and complex arrays)")
        group.create_dataset(name, data=data)


def write_checkpoint(path: str | os.PathLike, arrays: dict[str, np.ndarray],
                     scalars: dict[str, float | int | str | bool],
                     groups: dict[str, dict[str, np.ndarray]] | None = None) -> Path:
    """Write a restart checkpoint (atomically); :func:`read_checkpoint` is its exact inverse.

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.h5`` file (replaced if it exists).
    arrays : dict of str to ndarray
        Numeric arrays (bool, integer, float, complex), e.g.
        ``Particles.arrays()``.
    scalars : dict
        Python ``float``, ``int``, ``str`` or ``bool`` values (time, step,
        energy accumulators, deck hash, ...). The Python type is restored.
    groups : dict of str to dict of str to ndarray, optional
        Further named collections of arrays (contact state, FEM meshes, ...).

    Returns
    -------
    pathlib.Path
        The path written.
    """
    for name, value in scalars.items():
        _check_name(name, "scalar")
        if not isinstance(value, (bool, int, float, str, np.bool_, np.integer,
                                  np.floating)):
            raise TypeError(f"scalar {name!r} has unsupported type "
                            f"{type(value).__name__} (float, int, str or bool)")
    path = Path(path)
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["sphdyn_format"] = "checkpoint"
            f.attrs["format_version"] = FORMAT_VERSION
            _write_arrays(f.create_group("arrays", track_order=True), arrays, "array")
            g_scalars = f.create_group("scalars", track_order=True)
            for name, value in scalars.items():
                if isinstance(value, (bool, np.bool_)):
                    g_scalars.attrs[name] = np.bool_(value)
                elif isinstance(value, (int, np.integer)):
                    g_scalars.attrs[name] = np.int64(value)
                elif isinstance(value, (float, np.floating)):
                    g_scalars.attrs[name] = np.float64(value)
                else:
                    g_scalars.attrs[name] = value
            g_groups = f.create_group("groups", track_order=True)
            for gname, garrays in (groups or {}).items():
                _check_name(gname, "group")
                _write_arrays(g_groups.create_group(gname, track_order=True), garrays,
                              f"group {gname!r} array")
    return path


def read_checkpoint(path: str | os.PathLike
                    ) -> tuple[dict[str, np.ndarray], dict[str, Any],
                               dict[str, dict[str, np.ndarray]]]:
    """Read a checkpoint written by :func:`write_checkpoint`.

    Returns
    -------
    arrays : dict of str to ndarray
    scalars : dict of str to float, int, str or bool
    groups : dict of str to dict of str to ndarray
        Empty if none were written.
    """
    path = Path(path)
    with h5py.File(path, "r") as f:
        _check_format(f, "checkpoint", path)
        arrays = {k: v[()] for k, v in f["arrays"].items()}
        scalars = {k: _to_python(v) for k, v in f["scalars"].attrs.items()}
        groups = {g: {k: v[()] for k, v in grp.items()}
                  for g, grp in f["groups"].items()}
    return arrays, scalars, groups
