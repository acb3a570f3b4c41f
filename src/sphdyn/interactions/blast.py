r"""Empirical air-blast load on exposed faces (LS-DYNA's LOAD_BLAST_ENHANCED).

A TNT charge of mass :math:`W` at :math:`\mathbf x_c`, detonated at
:math:`t_d`, loads every face of a set with the Kingery-Bulmash pressure
(:mod:`sphdyn.interactions.kingery_bulmash`): at the face's centre :math:`\mathbf c` with
outward unit normal :math:`\mathbf n` and area :math:`A`, the range
:math:`R = |\mathbf c - \mathbf x_c|`, the scaled distance
:math:`Z = R/W^{1/3}`, the cosine of the angle of incidence
:math:`\cos\theta = \mathbf n\cdot(\mathbf x_c - \mathbf c)/R`, and the
force :math:`\mathbf f = -p(Z, \theta, t - t_d)\,A\,\mathbf n` (inward: an
overpressure pushes on the face).

Faces
-----
* Mesh nodes (hex8 / quad4 meshes): the mesh's exterior faces whose nodes
  all belong to the set; centre, normal and area from the current node
  positions (quadrilateral: :math:`A\mathbf n = \tfrac12 \mathbf d_1\times
  \mathbf d_2` with the diagonals :math:`\mathbf d_1 = \mathbf x_2 -
  \mathbf x_0`, :math:`\mathbf d_2 = \mathbf x_3 - \mathbf x_1`, exact for a
  flat face; a 2D edge: length per unit thickness); the force is shared
  equally by the face's nodes.
* Particles (SPH bodies on a lattice): a particle of spacing
  :math:`\Delta x = V_0^{1/d}` has an exposed face in the direction
  :math:`\pm\mathbf e_k` where no particle lies within
  :math:`\Delta x/2` of :math:`\mathbf x \pm \Delta x\,\mathbf e_k` (found
  once, at the start; an initial crack's zero-mass particles count there:
  the blast does not enter a crack); its area is :math:`\Delta x^{d-1}`,
  its centre :math:`\mathbf x \pm \tfrac12\Delta x\,\mathbf e_k` moves with the
  particle, its normal keeps its initial direction (a particle has no
  orientation; a slab loaded by a blast turns by far less than a degree).

Faces turned away from the charge (:math:`\cos\theta < 0`) take the
incident pressure, as in LS-DYNA, or nothing (``turned_away = "unloaded"``,
a face in the shadow of its own body). There is no other shadowing: the
set says which faces the wave reaches.

The work of the load is external work (``W_external``); column
``W_<name>`` is its total, ``<name>_force_x|y|z`` the force now and
``<name>_impulse_x|y|z`` its time integral [N s] (N s/m in 2D).

The model and its tests: docs/theory.md, "Empirical blast loads".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from . import kingery_bulmash as kb
from .base import InteractionBase


@njit(cache=True, error_model="numpy")
def particle_blast(x, m, active, item, normal, half, area, xc, w13, burst, tau,
                   unload_away, par, force, a_out):
    r"""Blast forces on particle faces: face ``f`` of particle ``item[f]``
    has the fixed outward normal ``normal[f]`` (3,), its centre at
    ``x[item] + half[f] * normal[f]``, area ``area[f]`` [m^2]; ``xc`` (3,) the
    charge [m], ``w13`` :math:`W^{1/3}`, ``tau`` = t - t_d [s]. Writes
    ``force`` (F, 3) [N] (0 on particles no longer ``active``), adds
    ``force / m`` to ``a_out`` (N, 3) (serial: several faces may share a
    particle); ``par`` (8,) scratch."""
    for f in range(item.shape[0]):
        i = item[f]
        if active[i] == 0:
            force[f, 0] = force[f, 1] = force[f, 2] = 0.0
            continue
        c0 = x[i, 0] + half[f] * normal[f, 0]
        c1 = x[i, 1] + half[f] * normal[f, 1]
        c2 = x[i, 2] + half[f] * normal[f, 2]
        p = _pressure(c0, c1, c2, normal[f, 0], normal[f, 1], normal[f, 2], xc, w13,
                      burst, tau, unload_away, par)
        for k in range(3):
            force[f, k] = -p * area[f] * normal[f, k]
            a_out[i, k] += force[f, k] / m[i]


@njit(cache=True, error_model="numpy")
def _pressure(c0, c1, c2, n0, n1, n2, xc, w13, burst, tau, unload_away, par):
    """Pressure on a face with centre c and unit outward normal n (module docstring)."""
    r0, r1, r2 = xc[0] - c0, xc[1] - c1, xc[2] - c2
    r = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    cos_t = (n0 * r0 + n1 * r1 + n2 * r2) / r
    if unload_away and cos_t < 0.0:
        return 0.0
    kb.parameters(r / w13, w13, burst, kb.BOUND, kb.AB, kb.COEF, par, False)
    return kb.face_pressure(par, cos_t, tau)


@njit(cache=True, error_model="numpy")
def face_frame(x, face):
    r"""Centre, unit outward normal and area of a mesh face as 7 scalars
    ``(cx, cy, cz, nx, ny, nz, area)``: a quadrilateral (4 nodes,
    :math:`A\mathbf n = \tfrac12\mathbf d_1\times\mathbf d_2` with the
    diagonals :math:`\mathbf d_1 = \mathbf x_2 - \mathbf x_0`,
    :math:`\mathbf d_2 = \mathbf x_3 - \mathbf x_1`) or a 2D segment (2
    nodes, normal :math:`(t_y, -t_x)/|t|`, area = length per unit
    thickness); node order of :mod:`~sphdyn.interactions.penalty_geometry`.
    Scalars, so that the per-step loop allocates nothing."""
    nf = face.shape[0]
    c0 = c1 = c2 = 0.0
    for a in range(nf):
        c0 += x[face[a], 0] / nf
        c1 += x[face[a], 1] / nf
        c2 += x[face[a], 2] / nf
    if nf == 2:
        n0 = x[face[1], 1] - x[face[0], 1]
        n1 = x[face[0], 0] - x[face[1], 0]
        n2 = 0.0
    else:
        a0 = x[face[2], 0] - x[face[0], 0]
        a1 = x[face[2], 1] - x[face[0], 1]
        a2 = x[face[2], 2] - x[face[0], 2]
        b0 = x[face[3], 0] - x[face[1], 0]
        b1 = x[face[3], 1] - x[face[1], 1]
        b2 = x[face[3], 2] - x[face[1], 2]
        n0 = 0.5 * (a1 * b2 - a2 * b1)
        n1 = 0.5 * (a2 * b0 - a0 * b2)
        n2 = 0.5 * (a0 * b1 - a1 * b0)
    area = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    return c0, c1, c2, n0 / area, n1 / area, n2 / area, area


def face_geometry(x, face):
    """:func:`face_frame` as arrays: centre (3,), unit normal (3,), area."""
    c0, c1, c2, n0, n1, n2, area = face_frame(x, np.asarray(face, dtype=np.int64))
    return np.array([c0, c1, c2]), np.array([n0, n1, n2]), area


@njit(cache=True, error_model="numpy")
def mesh_blast(x, m, faces, elements, active, xc, w13, burst, tau, unload_away, par,
               force, a_out):
    """Blast forces on mesh faces ``faces`` (F, nf) [N], each shared equally
    by its nodes: writes ``force`` (F, 3) (0 on faces whose element
    ``elements[f]`` is no longer ``active``: eroded), adds ``force / (nf m)``
    to the nodes' ``a_out`` (serial: faces share nodes)."""
    nf = faces.shape[1]
    for f in range(faces.shape[0]):
        if active[elements[f]] == 0:
            force[f, 0] = force[f, 1] = force[f, 2] = 0.0
            continue
        c0, c1, c2, n0, n1, n2, area = face_frame(x, faces[f])
        p = _pressure(c0, c1, c2, n0, n1, n2, xc, w13, burst, tau, unload_away, par)
        force[f, 0] = -p * area * n0
        force[f, 1] = -p * area * n1
        force[f, 2] = -p * area * n2
        for k in range(3):
            for a in range(nf):
                a_out[faces[f, a], k] += force[f, k] / (nf * m[faces[f, a]])


@njit(cache=True, error_model="numpy")
def blast_work(force, items, v_mid, dt_kick, impulse):
    r"""Work of the face forces over a kick [J]: :math:`\sum_f \mathbf f_f\cdot
    \bar{\mathbf v}_f\,\Delta t` with :math:`\bar{\mathbf v}_f` the mean
    mid-kick velocity of the face's items ``items[f]`` (nf,) (one particle,
    or the face's nodes, which share its force equally); adds the kick's
    impulse :math:`\sum_f \mathbf f_f\,\Delta t` to ``impulse`` (3,)."""
    w = 0.0
    s0 = s1 = s2 = 0.0
    nf = items.shape[1]
    for f in range(force.shape[0]):
        s0 += force[f, 0]
        s1 += force[f, 1]
        s2 += force[f, 2]
        for a in range(nf):
            i = items[f, a]
            w += (force[f, 0] * v_mid[i, 0] + force[f, 1] * v_mid[i, 1]
                  + force[f, 2] * v_mid[i, 2]) / nf
    impulse[0] += s0 * dt_kick
    impulse[1] += s1 * dt_kick
    impulse[2] += s2 * dt_kick
    return w * dt_kick


def particle_faces(x, vol0, m, idx, dim: int):
    """The exposed lattice faces of the particles ``idx`` (module docstring).

    Parameters
    ----------
    x : (N, 3) positions [m]; vol0 : (N,) volumes [m^dim]; m : (N,) masses
        (particles without mass, an initial crack's, take no load but close
        their neighbours' faces: the blast does not enter a crack);
        idx : (k,) candidates.

    Returns
    -------
    item : (F,) particle of each face; normal : (F, 3) unit outward normal;
    half : (F,) half spacing [m]; area : (F,) [m^(dim-1)].
    """
    idx = np.asarray(idx, dtype=np.int64)
    idx = idx[m[idx] > 0.0]
    tree = cKDTree(x[:, :dim])
    dx = vol0[idx] ** (1.0 / dim)
    items, normals, halves = [], [], []
    for k in range(dim):
        for sign in (1.0, -1.0):
            probe = x[idx, :dim].copy()
            probe[:, k] += sign * dx
            dist, _ = tree.query(probe, k=1)
            open_ = dist > 0.5 * dx
            n = np.zeros((int(open_.sum()), 3))
            n[:, k] = sign
            items.append(idx[open_])
            normals.append(n)
            halves.append(0.5 * dx[open_])
    item = np.concatenate(items)
    half = np.concatenate(halves)
    return item, np.concatenate(normals), half, (2.0 * half) ** (dim - 1)


class BlastLoad(InteractionBase):
    """The Kingery-Bulmash blast of one charge on the faces of one set.

    Parameters
    ----------
    name : column prefix.
    part : the SPH part (``particles``) or a solid mesh part (``faces``).
    charge : TNT-equivalent mass W [kg]; ``point`` (3,) its centre [m];
        ``time`` t_d [s]; ``burst``: ``"free_air"`` or ``"surface"``.
    faces : (F, nf) mesh faces (node ids), or None for particle faces of
        the set ``idx``; ``elements`` (F,) their elements (a face of an
        eroded element is not loaded).
    turned_away : ``"incident"`` or ``"unloaded"`` (module docstring).

    Raises ``ValueError`` if the set has no exposed face, or a face lies
    outside the fits' range of scaled distance.
    """

    external = True  # its work is external work (W_external)

    def __init__(self, name: str, part, charge: float, point, *, burst: str = "free_air",
                 time: float = 0.0, idx=None, faces=None, elements=None,
                 turned_away: str = "incident"):
        self.name, self.part = name, part
        self.w13 = float(charge) ** (1.0 / 3.0)
        self.xc = np.asarray(point, dtype=float)
        self.burst = kb.BURSTS[burst]
        self.t_det = float(time)
        self.unload_away = turned_away == "unloaded"
        q = part.kin
        self.faces = None if faces is None else np.ascontiguousarray(faces, dtype=np.int64)
        if self.faces is None:
            self.item, self.normal, self.half, self.area = particle_faces(
                q.x, part.p.vol0, q.m, idx, q.dim)
            self.items = self.item.reshape(-1, 1)
            centres = q.x[self.item] + self.half[:, None] * self.normal
        else:
            self.items = self.faces
            self.elements = np.ascontiguousarray(elements, dtype=np.int64)
            centres = q.x[self.faces].mean(axis=1)
        if not self.items.shape[0]:
            raise ValueError(f"{name}: the set has no exposed face")
        z = np.linalg.norm(centres - self.xc, axis=1) / self.w13
        lo, hi = kb.Z_RANGE[self.burst]
        if z.min() < lo or z.max() > hi:
            raise ValueError(
                f"{name}: faces lie at scaled distances {z.min():.3g} to {z.max():.3g} "
                f"m/kg^(1/3); the Kingery-Bulmash fits hold from {lo} to {hi}")
        self.force = np.zeros((self.items.shape[0], 3))
        self._par = np.zeros(8)
        self.impulse = np.zeros(3)
        self.work = 0.0
        self._kick = 0.0

    @property
    def n_faces(self) -> int:
        return int(self.items.shape[0])

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        q = self.part.kin
        tau = t - self.t_det
        if self.faces is None:
            particle_blast(q.x, q.m, q.active, self.item, self.normal, self.half, self.area,
                           self.xc, self.w13, self.burst, tau, self.unload_away, self._par,
                           self.force, a_out)
        else:
            mesh_blast(q.x, q.m, self.faces, self.elements, self.part.el.active, self.xc,
                       self.w13, self.burst, tau, self.unload_away, self._par, self.force,
                       a_out)

    def after_kick(self, dt_kick: float) -> None:
        self._kick = blast_work(self.force, self.items, self.part.kin.v_mid, dt_kick,
                                self.impulse)
        self.work += self._kick

    def external_work(self) -> float:
        return self._kick

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        out = {f"W_{self.name}": self.work}
        for k, c in enumerate("xyz"):
            out[f"{self.name}_force_{c}"] = float(f[k])
        for k, c in enumerate("xyz"):
            out[f"{self.name}_impulse_{c}"] = float(self.impulse[k])
        return out

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"work": self.work, "kick": self._kick}, {"force": self.force,
                                                         "impulse": self.impulse}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self.work = float(scalars["work"])
        self._kick = float(scalars["kick"])
        self.force[...] = arrays["force"]
        self.impulse[...] = arrays["impulse"]
