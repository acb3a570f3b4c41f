"""What a validation case reads off a finished run, as an experimenter would
measure it on the specimen.

* :func:`depth_of_penetration`: the deepest point the projectile reached
  below the target's face, from the history of a ``[[probe]]`` with
  ``reduce = "min"`` of ``position_<axis>`` over the projectile's set:
  ``DOP = z_face - min_t min_i z_i + dx / 2`` [m] (a particle's material
  reaches half a spacing beyond its centre).
* :func:`lost_face_diameter`: the diameter of the crater (front face) or the
  scabbed area (rear face) of a solid mesh target, from its last frame. A
  node of the face counts as lost when no live element holds it (its
  elements eroded) or when it moved out of the face's plane by more than
  one element size (a spall or scab piece flying off). The diameter is
  ``2 (max r_lost + h / 2)`` with ``r`` the node's initial distance from the
  shot line and ``h`` the element size in the face: the crater's edge lies
  between the last lost node and the first kept one, so the reading error
  is +-h/2.
* :func:`largest_deflection`: the largest mid-span deflection and its time
  after the impact, from the mean vertical displacement of a mid-span set
  (a probe); the impact starts at the first history record with a contact
  force on the impactor's mesh.
* :func:`load_deflection` and :func:`peak_load`: a quasi-static test's load
  against mid-span deflection, the load being the contact force on the
  loading mesh averaged over windows of fixed length (the contact of a
  particle surface is a train of spikes; the testing machine's load cell
  averages it over its own response time), and its peak with the
  deflection there.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.frames import list_frames
from ..io.hdf5 import read_frame_meshes
from ..io.history import History

AXES = {"x": 0, "y": 1, "z": 2}


def depth_of_penetration(run: Path, probe_set: str, face: float, dx: float,
                         axis: str = "z") -> float:
    """Deepest penetration [m] below a face at ``face`` [m] whose outward
    normal is +``axis``, of the set ``probe_set`` of particles of spacing
    ``dx`` [m] (module docstring); ``KeyError`` naming the missing column."""
    column = f"probe_{probe_set}_position_{axis}"
    h = History.from_csv(Path(run) / "history.csv").as_arrays()
    if column not in h:
        raise KeyError(f"{run}: history has no column {column!r}: the deck needs a "
                       f"[[probe]] of set {probe_set!r}, position_{axis}, reduce = 'min'")
    return float(face - np.nanmin(h[column]) + 0.5 * dx)


def lost_face_diameter(run: Path, mesh: str, face: float, normal: float, h: float,
                       centre=(0.0, 0.0), axis: str = "z") -> float:
    """Diameter [m] of the lost area of the mesh face at ``axis = face`` [m]
    (``normal`` = +1 or -1: the face's outward direction along ``axis``),
    about the shot line through ``centre`` (its two other coordinates),
    for a mesh of element size ``h`` [m] in the face (its smallest, on a
    graded mesh: the face's tolerance and the moved-out distance; the
    half-element added is the face's node spacing at the farthest lost node,
    outwards along the axis nearer its radius)
    (module docstring); 0 when no node of the face is lost."""
    frames = list_frames(Path(run))
    if not frames:
        raise FileNotFoundError(f"{run}: no frames to measure")
    m = read_frame_meshes(frames[-1])[mesh]
    k = AXES[axis]
    x = np.asarray(m.points, float)
    x0 = x - np.asarray(m.point_data["displacement"], float)
    on_face = np.abs(x0[:, k] - face) < 1e-3 * h
    held = np.zeros(len(x), bool)
    held[np.unique(m.cells)] = True
    moved_out = normal * (x[:, k] - x0[:, k]) > h
    lost = on_face & (~held | moved_out)
    if not lost.any():
        return 0.0
    others = [i for i in range(3) if i != k]
    r = np.hypot(x0[lost, others[0]] - centre[0], x0[lost, others[1]] - centre[1])
    return float(2.0 * (r.max() + 0.5 * _spacing_outward(x0[on_face], x0[np.flatnonzero(
        lost)[np.argmax(r)]], others, centre, h)))


def _spacing_outward(face_nodes, node, others, centre, h: float) -> float:
    """The face's node spacing [m] at ``node`` along the in-face axis nearer
    to its radial direction from ``centre``, to the next node outwards (inwards
    at the face's edge): h on an equal grid, the local size on a graded one."""
    off = [node[i] - c for i, c in zip(others, centre)]
    a, b = (0, 1) if abs(off[0]) >= abs(off[1]) else (1, 0)
    row = face_nodes[np.abs(face_nodes[:, others[b]] - node[others[b]]) < 1e-3 * h]
    step = (row[:, others[a]] - node[others[a]]) * (1.0 if off[a] >= 0.0 else -1.0)
    out, back = step[step > 1e-3 * h], -step[step < -1e-3 * h]
    if out.size:
        return float(out.min())
    return float(back.min()) if back.size else h


def contact_force(h: dict, mesh: str) -> np.ndarray:
    """The normal force [N] of a mesh's ``[mesh.contact]`` on everything it
    meets: ``F_<mesh>_contact`` (the particles) plus ``F_<mesh>_contact_<slave>``
    of each mesh in its ``meshes`` (their nodes), from a history's columns."""
    own = f"F_{mesh}_contact"
    names = [k for k in h if k == own or (k.startswith(own + "_") and not k.endswith("_tie"))]
    if not names:
        raise KeyError(f"the history has no contact force of mesh {mesh!r} ({own})")
    return np.sum([h[k] for k in names], axis=0)


def deflection_history(run: Path, midspan: str, impactor: str, axis: str = "z"
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(time after the contact's start [s], deflection [m], positive
    downwards along -``axis``) from the probe ``probe_<midspan>_displacement_<axis>``
    and the impactor mesh's contact force (:func:`contact_force`): the
    contact starts at the first record where that force is positive;
    records before it are dropped."""
    h = History.from_csv(Path(run) / "history.csv").as_arrays()
    t, force = h["time"], contact_force(h, impactor)
    started = np.flatnonzero(force > 0.0)
    if not started.size:
        raise ValueError(f"{run}: the impactor {impactor!r} never touched: no contact force")
    i0 = started[0]
    return t[i0:] - t[i0], -h[f"probe_{midspan}_displacement_{axis}"][i0:]


def largest_deflection(run: Path, midspan: str, impactor: str, axis: str = "z"
                       ) -> tuple[float, float]:
    """(largest deflection [m], its time after the contact's start [s])
    (:func:`deflection_history`)."""
    t, u = deflection_history(run, midspan, impactor, axis)
    k = int(np.argmax(u))
    return float(u[k]), float(t[k])


def load_deflection(run: Path, loader: str, midspan: str, window: float, axis: str = "z"
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(deflection [m], load [N]) of a quasi-static test: the contact force
    of the loading mesh (:func:`contact_force`) and the mid-span probe's displacement (positive
    along -``axis``), each averaged over consecutive windows of ``window``
    [s] of the history's records (a window's mean of the records in it; a
    last partial window is dropped)."""
    h = History.from_csv(Path(run) / "history.csv").as_arrays()
    t = h["time"]
    force = contact_force(h, loader)
    u = -h[f"probe_{midspan}_displacement_{axis}"]
    k = np.floor((t - t[0]) / window).astype(np.int64)
    full = k < k[-1]
    if not full.any():
        raise ValueError(f"{run}: the history is shorter than one window of {window} s")
    k, force, u = k[full], force[full], u[full]
    counts = np.bincount(k)
    ok = counts > 0
    return (np.bincount(k, u)[ok] / counts[ok], np.bincount(k, force)[ok] / counts[ok])


def peak_load(run: Path, loader: str, midspan: str, window: float, axis: str = "z"
              ) -> tuple[float, float]:
    """(largest window-averaged load [N], the deflection there [m])
    (:func:`load_deflection`)."""
    u, f = load_deflection(run, loader, midspan, window, axis)
    k = int(np.argmax(f))
    return float(f[k]), float(u[k])
