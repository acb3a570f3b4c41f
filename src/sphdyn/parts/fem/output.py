"""What a mesh part shows: its picture in a frame and its line in the summary."""

from __future__ import annotations

import numpy as np

from ...io.meshes import MeshFrame


def mesh_frame(part, elements, kind: str) -> MeshFrame:
    """The :class:`~sphdyn.io.MeshFrame` of a mesh part: nodes at their current
    positions with ``displacement``, ``velocity`` and ``mass`` [m, m/s, kg; the
    lumped nodal mass, kg/m in 2D], and every cell field of the part
    (``part.fields()``: stress, von_mises, damage, history columns,
    hourglass_energy; beams: forces) on the live cells of ``elements`` (its
    element table, ``kind`` a :data:`~sphdyn.geometry.mesh.MESH_KINDS` name);
    eroded elements are left out."""
    q = part.kin
    live = elements.active == 1
    return MeshFrame(
        points=q.x.copy(), cells=elements.conn[live], kind=kind,
        point_data={"displacement": q.x - q.x0, "velocity": q.v.copy(),
                    "mass": q.m.copy()},
        cell_data={name: np.asarray(fn())[live] for name, fn in part.fields().items()})


def mesh_summary(part, elements) -> dict:
    """A mesh part's entry in the run's summary: its node and element counts."""
    return {"nodes": int(part.kin.n), "elements": int(elements.n)}
