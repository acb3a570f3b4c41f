"""Output and restart I/O: frames, ParaView files, histories, checkpoints, plots.

Nothing is lost: every file is written to a temporary file in the same
directory and atomically renamed onto its destination
(:mod:`sphdyn.io.atomic`), so a crash never leaves a truncated file.

* :mod:`~sphdyn.io.hdf5` -- native frames and bitwise-exact checkpoints,
* :mod:`~sphdyn.io.vtk` -- ``.vtu`` particle and mesh files, ``.pvd`` time
  series (several blocks per time step),
* :mod:`~sphdyn.io.meshes` -- :class:`MeshFrame`, the mesh blocks of a frame,
* :mod:`~sphdyn.io.fields` -- the fields of a frame, from the state and the
  field registry :mod:`sphdyn.fields`,
* :mod:`~sphdyn.io.frames` -- numbered frames of a run directory, restart,
  VTK/CSV export,
* :mod:`~sphdyn.io.history` -- global time histories (CSV),
* :mod:`~sphdyn.io.plots` -- figures of a history (Matplotlib, Agg),
* :mod:`~sphdyn.io.snapshots` -- panels of particle frames coloured by a field,
  :mod:`~sphdyn.io.frame_data` -- the frames, slab and field values they show.
"""

from .atomic import atomic_path, atomic_write_bytes, atomic_write_text
from .fields import particle_fields
from .frames import FrameWriter, export_csv, export_vtk, list_frames
from .hdf5 import (read_checkpoint, read_frame, read_frame_header,
                   read_frame_meshes, write_checkpoint, write_frame)
from .history import History, read_history_csv
from .meshes import MESH_KINDS, MeshFrame
from .plots import plot_history  # imports Matplotlib only when called
from .snapshots import plot_snapshots  # likewise
from .vtk import (PvdDataSet, read_pvd, read_pvd_datasets, write_mesh_vtu, write_pvd,
                  write_vtu)


__all__ = [
    "atomic_path", "atomic_write_bytes", "atomic_write_text",
    "particle_fields",
    "FrameWriter", "export_csv", "export_vtk", "list_frames",
    "read_checkpoint", "read_frame", "read_frame_header", "read_frame_meshes",
    "write_checkpoint", "write_frame",
    "MESH_KINDS", "MeshFrame",
    "History", "read_history_csv",
    "PvdDataSet", "read_pvd", "read_pvd_datasets", "write_mesh_vtu", "write_pvd",
    "write_vtu",
    "plot_history", "plot_snapshots",
]
