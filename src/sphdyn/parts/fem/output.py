"""What a mesh part shows: its picture in a frame and its line in the summary."""

from __future__ import annotations

import numpy as np

from ...fields import FIELDS, default_fields
from ...io.meshes import MeshFrame


def cell_fields_written(available, names=None) -> list[str]:
    """The cell fields of ``available`` (a part's ``fields()`` names) a mesh
    frame writes: those named in ``names`` (the deck's ``output.fields``;
    None: the registry's defaults), and every history column of the part's
    materials (registered or not: :mod:`sphdyn.fields`)."""
    wanted = set(default_fields() if names is None else names)
    return [n for n in available
            if n in wanted or n not in FIELDS or FIELDS[n].shape == "history"]


def mesh_frame(part, elements, kind: str, names=None) -> MeshFrame:
    """The :class:`~sphdyn.io.MeshFrame` of a mesh part: nodes at their current
    positions with ``displacement``, ``velocity`` and ``mass`` [m, m/s, kg; the
    lumped nodal mass, kg/m in 2D], and the part's cell fields
    (``part.fields()``: stress, von_mises, damage, history columns,
    hourglass_energy; beams: forces) that :func:`cell_fields_written` picks
    from ``names``, on the live cells of ``elements`` (its element table,
    ``kind`` a :data:`~sphdyn.geometry.mesh.MESH_KINDS` name); eroded
    elements are left out."""
    q = part.kin
    live = elements.active == 1
    fields = part.fields()
    return MeshFrame(
        points=q.x.copy(), cells=elements.conn[live], kind=kind,
        point_data={"displacement": q.x - q.x0, "velocity": q.v.copy(),
                    "mass": q.m.copy()},
        cell_data={name: np.asarray(fields[name]())[live]
                   for name in cell_fields_written(fields, names)})


def mesh_summary(part, elements) -> dict:
    """A mesh part's entry in the run's summary: its node and element counts."""
    return {"nodes": int(part.kin.n), "elements": int(elements.n)}
