"""Frame output of a run directory, with restart and ParaView export.

Layout of an output directory::

    outdir/frames/frame_00000.h5   native frames (always), see sphdyn.io.hdf5
    outdir/vtk/frame_00000.vtu     ParaView frames (if vtk=True)
    outdir/particles.pvd           ParaView time series of the .vtu files

Every file is written atomically. The ``.pvd`` is rewritten after each frame,
so it always lists exactly the complete ``.vtu`` files. Runs made without VTK
output can be converted afterwards with :func:`export_vtk`.
"""

from __future__ import annotations

import io
import os
import re
from pathlib import Path

import numpy as np

from .atomic import atomic_write_text
from .hdf5 import read_frame, read_frame_header, write_frame
from .vtk import write_pvd, write_vtu

__all__ = ["FrameWriter", "list_frames", "export_vtk", "export_csv"]

FRAMES_DIR = "frames"
VTK_DIR = "vtk"
PVD_NAME = "particles.pvd"
_FRAME_RE = re.compile(r"^frame_(\d{5,})\.h5$")


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


def _frame_index(path: Path) -> int:
    m = _FRAME_RE.match(path.name)
    assert m is not None
    return int(m.group(1))


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
        Also write ``vtk/frame_*.vtu`` and keep ``particles.pvd`` up to date.
    start_after : float, optional
        Restart time [s]. Frames with ``time <= start_after`` are kept and
        numbering continues after the last of them; frames with a later time
        belong to the abandoned part of the previous run and are deleted
        (``.h5`` and ``.vtu``) and dropped from the ``.pvd``.
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
            t, _, _ = read_frame_header(f)
            if start_after is not None and t <= start_after:
                kept.append((t, _frame_index(f)))
            else:
                dropped.append(_frame_index(f))
        self._times = [t for t, _ in kept]
        self._indices = [i for _, i in kept]
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

    def _write_pvd(self) -> None:
        entries = []
        for t, i in zip(self._times, self._indices):
            vtu = self.vtk_dir / _frame_name(i, ".vtu")
            if vtu.exists():
                entries.append((t, f"{VTK_DIR}/{vtu.name}"))
        write_pvd(self.pvd_path, entries)

    def write(self, t: float, step: int, fields: dict[str, np.ndarray]) -> int:
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
        index = self.next_index
        write_frame(self.frames_dir / _frame_name(index, ".h5"), t, step, fields)
        if self.vtk:
            write_vtu(self.vtk_dir / _frame_name(index, ".vtu"), x, point_data)
        self._times.append(float(t))
        self._indices.append(index)
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
    """(Re)generate ``vtk/*.vtu`` and ``particles.pvd`` from the native frames.

    Returns
    -------
    pathlib.Path
        The ``.pvd`` file written.
    """
    outdir = Path(outdir)
    entries = []
    for f in list_frames(outdir):
        t, _, fields, _ = read_frame(f)
        x, point_data = _split_position(fields)
        vtu = outdir / VTK_DIR / f.with_suffix(".vtu").name
        write_vtu(vtu, x, point_data)
        entries.append((t, f"{VTK_DIR}/{vtu.name}"))
    return write_pvd(outdir / PVD_NAME, entries)


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
    frames = list_frames(outdir)
    if not frames:
        raise FileNotFoundError(f"no frames in {outdir / FRAMES_DIR}")
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
