"""Frame output of a run directory, with restart and ParaView export.

Layout of an output directory::

    outdir/frames/frame_00000.h5        native frames (always), see sphdyn.io.hdf5
    outdir/vtk/frame_00000.vtu          ParaView particle frames (if vtk=True)
    outdir/vtk/<mesh>/frame_00000.vtu   ParaView frames of each mesh block
    outdir/particles.pvd                ParaView time series of the .vtu files

Every file is written atomically. The ``.pvd`` is rewritten after each frame,
so it always lists exactly the complete ``.vtu`` files. Runs made without VTK
output can be converted afterwards with :func:`export_vtk`.

Frames may carry finite-element mesh blocks beside the particles
(:class:`~sphdyn.io.meshes.MeshFrame`, by name). The ``.pvd`` then lists, at
every time step, the particles (part 0, name ``"particles"``) and each mesh
(parts 1, 2, ... in order of first appearance, named after the mesh), which
ParaView shows as one multiblock time series. A run without meshes writes
exactly the single-block files it always did.
"""

from __future__ import annotations

import io
import os
import re
from pathlib import Path

import numpy as np

from .atomic import atomic_write_text
from .hdf5 import (read_frame, read_frame_header, read_frame_mesh_names,
                   read_frame_meshes, write_frame)
from .meshes import PARTICLES_BLOCK, MeshFrame
from .vtk import PvdDataSet, write_mesh_vtu, write_pvd, write_vtu

__all__ = ["FrameWriter", "list_frames", "export_vtk", "export_csv"]

FRAMES_DIR = "frames"
VTK_DIR = "vtk"
PVD_NAME = "particles.pvd"
_FRAME_RE = re.compile(r"^frame_(\d{5,})\.h5$")
#: frame attribute of the last state of a run stopped before its end time
#: (--max-steps, a signal, a failure), written off the frame schedule
STOP_FRAME = "stop_frame"


def _frame_name(index: int, suffix: str) -> str:
    return f"frame_{index:05d}{suffix}"


def list_frames(outdir: str | os.PathLike) -> list[Path]:
    """Native frame files of ``outdir``, sorted by frame index."""
    frames_dir = Path(outdir) / FRAMES_DIR
    if not frames_dir.is_dir():
        return []
    found = []
    for f in frames_dir.iterdir():
        m = _FRAME_RE.match(f.name)
        if m and f.is_file():
            found.append((int(m.group(1)), f))
    return [f for _, f in sorted(found)]


def frames_of_run(outdir: str | os.PathLike) -> list[Path]:
    """:func:`list_frames`, or a FileNotFoundError saying why there are none
    and what to do (a missing directory, or a run that wrote no frame)."""
    outdir = Path(outdir)
    frames = list_frames(outdir)
    if frames:
        return frames
    if not outdir.is_dir():
        raise FileNotFoundError(f"{outdir}: no such directory. Fix: give the output "
                                "directory of a run (out/<deck name>, or the run's --out)")
    raise FileNotFoundError(
        f"{outdir}: there are no frames ({outdir / FRAMES_DIR}/frame_*.h5), so nothing "
        "to export or plot. Fix: give the output directory of a run, or run the deck "
        "(sphdyn run DECK --out DIR; a run writes its first frame at t = 0)")


def _frame_index(path: Path) -> int:
    m = _FRAME_RE.match(path.name)
    assert m is not None
    return int(m.group(1))


def _mesh_vtu(vtk_dir: Path, name: str, index: int) -> Path:
    """The ``.vtu`` file of mesh ``name`` in frame ``index``."""
    return vtk_dir / name / _frame_name(index, ".vtu")


def _write_mesh_vtus(vtk_dir: Path, index: int, meshes: dict[str, MeshFrame]) -> None:
    """Write ``vtk_dir/<name>/frame_<index>.vtu`` for every mesh block."""
    for name, m in meshes.items():
        write_mesh_vtu(_mesh_vtu(vtk_dir, name, index), m.points, m.cells, m.kind,
                       m.point_data, m.cell_data)


def _pvd_entries(vtk_dir: Path, frames: list[tuple[float, int, tuple[str, ...]]]
                 ) -> list[tuple[float, str] | PvdDataSet]:
    """``.pvd`` entries of the frames' ``.vtu`` files that exist.

    ``frames`` holds ``(time [s], index, mesh names)`` per frame. Without any
    mesh the entries are single-block ``(time, file)`` pairs; otherwise each
    time step lists the particles (part 0) and its meshes, a mesh keeping the
    part number of its first appearance.
    """
    multi = any(names for _, _, names in frames)
    parts = {PARTICLES_BLOCK: 0}
    entries: list[tuple[float, str] | PvdDataSet] = []
    for t, index, names in frames:
        blocks = [(PARTICLES_BLOCK, vtk_dir / _frame_name(index, ".vtu"))]
        blocks += [(name, _mesh_vtu(vtk_dir, name, index)) for name in names]
        for name, vtu in blocks:
            part = parts.setdefault(name, len(parts))
            if not vtu.exists():
                continue
            file = vtu.relative_to(vtk_dir.parent).as_posix()
            entries.append(PvdDataSet(t, file, part, name) if multi else (t, file))
    return entries


def _split_position(fields: dict[str, np.ndarray]
                    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    if "position" not in fields:
        raise ValueError("frame fields must contain 'position' for VTK output")
    return fields["position"], {k: v for k, v in fields.items() if k != "position"}


class FrameWriter:
    """Write numbered particle frames into an output directory.

    Parameters
    ----------
    outdir : str or os.PathLike
        Output directory (created if needed).
    vtk : bool, optional
        Also write ``vtk/frame_*.vtu`` (and ``vtk/<mesh>/frame_*.vtu`` for
        frames with meshes) and keep ``particles.pvd`` up to date.
    start_after : float, optional
        Restart time [s]. Frames with ``time <= start_after`` are kept and
        numbering continues after the last of them; frames with a later time
        belong to the abandoned part of the previous run and are deleted
        (``.h5`` and every ``.vtu``) and dropped from the ``.pvd``, and so is
        a stop frame (:data:`STOP_FRAME`: the last state of a run stopped
        early, off the frame schedule, which the restart continues).
    overwrite : bool, optional
        Fresh run (``start_after=None``) over a directory that already holds
        frames: if True (default) they are deleted, as the new run replaces
        the old one; if False, :class:`FileExistsError` is raised instead.

    Raises
    ------
    FileExistsError
        If ``start_after`` is None, ``overwrite`` is False and ``outdir``
        already holds frames.
    """

    def __init__(self, outdir: str | os.PathLike, vtk: bool = True,
                 start_after: float | None = None, overwrite: bool = True) -> None:
        self.outdir = Path(outdir)
        self.vtk = vtk
        self.frames_dir = self.outdir / FRAMES_DIR
        self.vtk_dir = self.outdir / VTK_DIR
        self.pvd_path = self.outdir / PVD_NAME
        self.frames_dir.mkdir(parents=True, exist_ok=True)
        if vtk:
            self.vtk_dir.mkdir(parents=True, exist_ok=True)

        existing = list_frames(self.outdir)
        if start_after is None and existing and not overwrite:
            raise FileExistsError(
                f"{self.frames_dir} already holds {len(existing)} frame(s); "
                "pass start_after=<restart time> to continue a run or "
                "overwrite=True to replace them")
        kept: list[tuple[float, int]] = []  # (time, index)
        dropped: list[int] = []
        for f in existing:
            t, _, attrs = read_frame_header(f)
            if start_after is not None and t <= start_after and not attrs.get(STOP_FRAME):
                kept.append((t, _frame_index(f)))
            else:
                dropped.append(_frame_index(f))
        self._times = [t for t, _ in kept]
        self._indices = [i for _, i in kept]
        # Mesh block names of every frame, for the .pvd.
        self._mesh_names = [tuple(read_frame_mesh_names(self.frames_dir /
                                                        _frame_name(i, ".h5")))
                            for _, i in kept]
        self.next_index = self._indices[-1] + 1 if kept else 0
        # The .pvd stops listing the dropped frames before they are deleted.
        if vtk or self.pvd_path.exists():
            self._write_pvd()
        for index in dropped:
            self._delete_frame(index)

    def _delete_frame(self, index: int) -> None:
        for f in (self.frames_dir / _frame_name(index, ".h5"),
                  self.vtk_dir / _frame_name(index, ".vtu")):
            f.unlink(missing_ok=True)
        if not self.vtk_dir.is_dir():
            return
        for d in [d for d in self.vtk_dir.iterdir() if d.is_dir()]:  # mesh blocks
            (d / _frame_name(index, ".vtu")).unlink(missing_ok=True)
            if not any(d.iterdir()):
                d.rmdir()  # the mesh has no frame left

    def _write_pvd(self) -> None:
        frames = list(zip(self._times, self._indices, self._mesh_names))
        write_pvd(self.pvd_path, _pvd_entries(self.vtk_dir, frames))

    def write(self, t: float, step: int, fields: dict[str, np.ndarray],
              meshes: dict[str, MeshFrame] | None = None,
              attrs: dict | None = None) -> int:
        """Write one frame; returns its index.

        Parameters
        ----------
        t : float
            Simulation time [s]; must not decrease from frame to frame.
        step : int
            Time-step number.
        fields : dict of str to ndarray
            Output fields (see :func:`sphdyn.io.fields.particle_fields`);
            ``"position"`` is required when writing VTK.
        meshes : dict of str to MeshFrame, optional
            Finite-element blocks of the frame by name (letters, digits,
            ``_ . -``; not ``"particles"``), written into the ``.h5`` frame
            and, with VTK output, as ``vtk/<name>/frame_<index>.vtu`` listed
            in the ``.pvd`` beside the particles. ParaView fixes the blocks of
            the series at the first time step: give the same meshes in every
            frame.
        attrs : dict, optional
            Extra attributes of the ``.h5`` frame (e.g. ``{STOP_FRAME: True}``).

        Returns
        -------
        int
            The frame index (``frame_<index>.h5``).
        """
        if self._times and t < self._times[-1]:
            raise ValueError(f"frame time {t} is before the previous frame "
                             f"time {self._times[-1]}")
        if self.vtk:
            x, point_data = _split_position(fields)
        meshes = dict(meshes or {})
        index = self.next_index
        write_frame(self.frames_dir / _frame_name(index, ".h5"), t, step, fields,
                    attrs=attrs, meshes=meshes)
        if self.vtk:
            write_vtu(self.vtk_dir / _frame_name(index, ".vtu"), x, point_data)
            _write_mesh_vtus(self.vtk_dir, index, meshes)
        self._times.append(float(t))
        self._indices.append(index)
        self._mesh_names.append(tuple(meshes))
        self.next_index = index + 1
        if self.vtk:
            self._write_pvd()
        return index

    @property
    def last_time(self) -> float | None:
        """Time [s] of the last frame written or kept, None if there is none."""
        return self._times[-1] if self._times else None

    @property
    def n_frames(self) -> int:
        """Number of frames of this run (kept on restart plus written)."""
        return len(self._times)

    def frames_on_disk(self) -> list[Path]:
        """Native frame files currently in the output directory, by index."""
        return list_frames(self.outdir)


def export_vtk(outdir: str | os.PathLike) -> Path:
    """(Re)generate ``vtk/*.vtu``, the mesh blocks' ``vtk/<mesh>/*.vtu`` and
    ``particles.pvd`` from the native frames.

    Returns
    -------
    pathlib.Path
        The ``.pvd`` file written.
    """
    outdir = Path(outdir)
    vtk_dir = outdir / VTK_DIR
    frames = []
    for f in frames_of_run(outdir):
        index = _frame_index(f)
        t, _, fields, _ = read_frame(f)
        x, point_data = _split_position(fields)
        write_vtu(vtk_dir / _frame_name(index, ".vtu"), x, point_data)
        meshes = read_frame_meshes(f)
        _write_mesh_vtus(vtk_dir, index, meshes)
        frames.append((t, index, tuple(meshes)))
    return write_pvd(outdir / PVD_NAME, _pvd_entries(vtk_dir, frames))


_TENSOR_SUFFIXES = ("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz")


def _csv_columns(name: str, data: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Column names and ``(N, k)`` table of one field."""
    n = data.shape[0]
    table = data.reshape(n, -1)
    k = table.shape[1]
    if data.ndim == 1:
        names = [name]
    elif k == 3:
        names = [f"{name}_{c}" for c in "xyz"]
    elif k == 9:
        names = [f"{name}_{c}" for c in _TENSOR_SUFFIXES]
    else:
        names = [f"{name}_{j}" for j in range(k)]
    return names, table


def export_csv(outdir: str | os.PathLike, frame: int = -1,
               path: str | os.PathLike | None = None) -> Path:
    """Write one native frame as a CSV table (one row per particle).

    Vectors become ``name_x, name_y, name_z`` columns, 9-component tensors
    ``name_xx ... name_zz``. Floats are written with 17 significant digits.

    Parameters
    ----------
    outdir : str or os.PathLike
        Output directory of a run.
    frame : int, optional
        Position in the sorted list of frames, Python style (``-1``: last).
    path : str or os.PathLike, optional
        Destination; default ``outdir/frame_<index>.csv``.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    outdir = Path(outdir)
    frames = frames_of_run(outdir)
    if not -len(frames) <= frame < len(frames):
        raise ValueError(f"frame {frame}: {outdir} has {len(frames)} frames. Fix: give "
                         f"--frame from 0 to {len(frames) - 1}, or -1 for the last")
    src = frames[frame]
    _, _, fields, _ = read_frame(src)
    header: list[str] = []
    tables: list[np.ndarray] = []
    formats: list[str] = []
    for name, data in fields.items():
        names, table = _csv_columns(name, np.asarray(data))
        header += names
        tables.append(table.astype(np.float64))
        formats += ["%.17g" if table.dtype.kind == "f" else "%d"] * len(names)
    buf = io.StringIO()
    buf.write(",".join(header) + "\n")
    if tables:
        np.savetxt(buf, np.hstack(tables), fmt=formats, delimiter=",")
    dest = Path(path) if path is not None else outdir / src.with_suffix(".csv").name
    atomic_write_text(dest, buf.getvalue())
    return dest
