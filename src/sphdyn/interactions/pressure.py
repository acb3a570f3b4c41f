r"""Pressure on element faces: consistent nodal forces on the deforming faces.

A pressure :math:`p` on a face :math:`\Gamma` of a solid mesh is the traction
:math:`\bar{\mathbf t} = -p\,\mathbf n` on the current surface (outward normal
:math:`\mathbf n`: positive pressure pushes into the body, as LS-DYNA's
LOAD_SEGMENT). Its consistent nodal forces are (Belytschko, Liu & Moran
2000, *Nonlinear Finite Elements for Continua and Structures*, the external
nodal forces :math:`\mathbf f_a = \int_\Gamma N_a \bar{\mathbf t}\, d\Gamma`)

.. math:: \mathbf f_a = -p \int_\Gamma N_a\, \mathbf n\, dA
          = -p \int_{-1}^{1}\!\int_{-1}^{1} N_a\,
          (\mathbf x_{,\xi}\times\mathbf x_{,\eta})\, d\xi\, d\eta ,

evaluated on the current node positions every step (a follower load: the
normal turns and the area changes with the face, and the load stiffness is
left to the explicit steps).

**Quadrilateral** (hex8 face, corners at :math:`(\xi_a, \eta_a) = (-,-), (+,-),
(+,+), (-,+)`, :math:`N_a = (1 + \xi\xi_a)(1 + \eta\eta_a)/4`): with
:math:`\mathbf e_1 = \tfrac14\sum_a \xi_a \mathbf x_a`,
:math:`\mathbf e_2 = \tfrac14\sum_a \eta_a \mathbf x_a`,
:math:`\mathbf h = \tfrac14\sum_a \xi_a\eta_a \mathbf x_a`, the tangents are
:math:`\mathbf x_{,\xi} = \mathbf e_1 + \eta\mathbf h`,
:math:`\mathbf x_{,\eta} = \mathbf e_2 + \xi\mathbf h`, so
:math:`\mathbf x_{,\xi}\times\mathbf x_{,\eta} = \mathbf e_1\times\mathbf e_2
+ \xi\,\mathbf e_1\times\mathbf h + \eta\,\mathbf h\times\mathbf e_2` and, with
:math:`\iint N_a = 1`, :math:`\iint N_a\xi = \xi_a/3`,
:math:`\iint N_a\eta = \eta_a/3`, exactly

.. math:: \mathbf f_a = -p\,\bigl(\mathbf e_1\times\mathbf e_2
          + \tfrac{\xi_a}{3}\,\mathbf e_1\times\mathbf h
          + \tfrac{\eta_a}{3}\,\mathbf h\times\mathbf e_2\bigr)

(what 2 x 2 Gauss points give; a flat parallelogram has :math:`\mathbf h = 0`
and each node takes a quarter of :math:`-p A \mathbf n`). The forces add up to
:math:`-p\,\mathbf S` with :math:`\mathbf S = 4\,\mathbf e_1\times\mathbf e_2 =
\tfrac12 \mathbf d_1\times\mathbf d_2` the face's area vector (diagonals
:math:`\mathbf d_1 = \mathbf x_2 - \mathbf x_0`, :math:`\mathbf d_2 = \mathbf x_3
- \mathbf x_1`).

**Segment** (quad4 edge in plane strain, per unit thickness, from node 0 to
node 1 counter-clockwise around the mesh, :math:`\mathbf t = \mathbf x_1 -
\mathbf x_0`): :math:`\mathbf f_0 = \mathbf f_1 = -\tfrac p2\,(t_y, -t_x, 0)`.

The faces are a mesh's exterior faces whose nodes all belong to a node set
(:func:`~sphdyn.interactions.penalty_geometry.exterior_faces`, outward
node order); a face of an eroded element is no longer loaded. The pressure
is scaled by a ramp or a time curve (:class:`~sphdyn.interactions.nodal.TimeFactor`).
Its work, :math:`\sum_n \sum_a \mathbf f_a\cdot\mathbf v_a^n\,\Delta t^n` at
the kicks, is external work (``W_external``). See docs/theory.md, "Pressure
on element faces".
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .base import InteractionBase
from .nodal import TimeFactor, set_work


@njit(cache=True, error_model="numpy")
def face_area_vectors(x, faces, f, S):
    r"""The vectors :math:`\mathbf S_a = \int_\Gamma N_a\,\mathbf n\,dA` [m^2]
    (m in 2D, per unit thickness) of the nodes of face ``f`` on the current
    positions ``x`` (N, 3), written to ``S`` (nf, 3) (module docstring: a
    quadrilateral's :math:`\mathbf e_1\times\mathbf e_2 + \tfrac{\xi_a}{3}
    \mathbf e_1\times\mathbf h + \tfrac{\eta_a}{3}\mathbf h\times\mathbf e_2`,
    a segment's :math:`\tfrac12 (t_y, -t_x, 0)`). ``faces`` (F, 4) or (F, 2),
    outward order; they add up to the face's area vector."""
    if faces.shape[1] == 2:
        i, j = faces[f, 0], faces[f, 1]
        for a in range(2):
            S[a, 0] = 0.5 * (x[j, 1] - x[i, 1])
            S[a, 1] = -(0.5 * (x[j, 0] - x[i, 0]))
            S[a, 2] = 0.0
        return
    i0, i1, i2, i3 = faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3]
    e1_0 = 0.25 * (-x[i0, 0] + x[i1, 0] + x[i2, 0] - x[i3, 0])
    e1_1 = 0.25 * (-x[i0, 1] + x[i1, 1] + x[i2, 1] - x[i3, 1])
    e1_2 = 0.25 * (-x[i0, 2] + x[i1, 2] + x[i2, 2] - x[i3, 2])
    e2_0 = 0.25 * (-x[i0, 0] - x[i1, 0] + x[i2, 0] + x[i3, 0])
    e2_1 = 0.25 * (-x[i0, 1] - x[i1, 1] + x[i2, 1] + x[i3, 1])
    e2_2 = 0.25 * (-x[i0, 2] - x[i1, 2] + x[i2, 2] + x[i3, 2])
    h_0 = 0.25 * (x[i0, 0] - x[i1, 0] + x[i2, 0] - x[i3, 0])
    h_1 = 0.25 * (x[i0, 1] - x[i1, 1] + x[i2, 1] - x[i3, 1])
    h_2 = 0.25 * (x[i0, 2] - x[i1, 2] + x[i2, 2] - x[i3, 2])
    # e1 x e2, e1 x h, h x e2
    s0 = e1_1 * e2_2 - e1_2 * e2_1
    s1 = e1_2 * e2_0 - e1_0 * e2_2
    s2 = e1_0 * e2_1 - e1_1 * e2_0
    b0 = (e1_1 * h_2 - e1_2 * h_1) / 3.0
    b1 = (e1_2 * h_0 - e1_0 * h_2) / 3.0
    b2 = (e1_0 * h_1 - e1_1 * h_0) / 3.0
    c0 = (h_1 * e2_2 - h_2 * e2_1) / 3.0
    c1 = (h_2 * e2_0 - h_0 * e2_2) / 3.0
    c2 = (h_0 * e2_1 - h_1 * e2_0) / 3.0
    for a in range(4):
        xi = -1.0 if a == 0 or a == 3 else 1.0
        eta = -1.0 if a < 2 else 1.0
        S[a, 0] = s0 + xi * b0 + eta * c0
        S[a, 1] = s1 + xi * b1 + eta * c1
        S[a, 2] = s2 + xi * b2 + eta * c2


@njit(cache=True, error_model="numpy")
def face_pressure_forces(x, faces, local, elements, active, p, S, force):
    r"""Consistent nodal forces of the pressure ``p`` [Pa] on the faces (module
    docstring), :math:`\mathbf f_a = -p\,\mathbf S_a` (:func:`face_area_vectors`),
    written to ``force`` (k, 3) [N] (N/m in 2D).

    ``x`` (N, 3) current node positions [m]; ``faces`` (F, 4) quadrilaterals
    or (F, 2) segments (node indices into ``x``, outward order); ``local``
    (F, nf) the row of each face node in ``force``; ``elements`` (F,) each
    face's element and ``active`` (E,) int8 (a face of an inactive element
    takes no load); ``S`` (nf, 3) scratch. Serial: faces share nodes."""
    for k in range(force.shape[0]):
        force[k, 0] = force[k, 1] = force[k, 2] = 0.0
    nf = faces.shape[1]
    for f in range(faces.shape[0]):
        if active[elements[f]] == 0:
            continue
        face_area_vectors(x, faces, f, S)
        for a in range(nf):
            r = local[f, a]
            force[r, 0] -= p * S[a, 0]
            force[r, 1] -= p * S[a, 1]
            force[r, 2] -= p * S[a, 2]


@njit(cache=True, error_model="numpy")
def accelerate(nodes, m, force, a_own, a_out):
    """``a_own[k] = force[k] / m[nodes[k]]`` (k, 3) [m/s^2], added to
    ``a_out[nodes[k]]`` (N, 3); 0 on a node without mass (every element about
    it eroded: its faces, and so its force, are gone)."""
    for k in range(nodes.shape[0]):
        i = nodes[k]
        massless = not m[i] > 0.0
        for j in range(3):
            a_own[k, j] = 0.0 if massless else force[k, j] / m[i]
            a_out[i, j] += a_own[k, j]


def face_rows(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The loaded nodes (k,) (sorted, unique) of ``faces`` (F, nf) and each face
    node's row among them (F, nf)."""
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    nodes = np.unique(faces)
    return nodes, np.ascontiguousarray(np.searchsorted(nodes, faces))


def nodal_forces(x, faces, p: float) -> np.ndarray:
    """Consistent nodal forces (N, 3) [N] of the pressure ``p`` [Pa] on ``faces``
    (F, 4) or (F, 2) of the nodes ``x`` (N, 3): :func:`face_pressure_forces`
    for every face, scattered onto all N nodes."""
    x = np.ascontiguousarray(x, dtype=float)
    nodes, local = face_rows(faces)
    n_faces = local.shape[0]
    force = np.zeros((nodes.size, 3))
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    face_pressure_forces(x, faces, local, np.zeros(n_faces, np.int64), np.ones(1, np.int8),
                         float(p), np.empty((faces.shape[1], 3)), force)
    out = np.zeros((x.shape[0], 3))
    out[nodes] = force
    return out


class FaceInteraction(InteractionBase):
    """Forces on faces of a solid mesh part whose work is external work: the
    faces, their nodes' rows, the accelerations of the last force pass and
    their work over the kicks (shared by :class:`PressureLoad` and the
    non-reflecting boundary).

    ``faces`` (F, 4) quadrilaterals or (F, 2) segments, outward node order;
    ``elements`` (F,) their elements; ``what`` names the forces in messages.
    """

    external = True  # its work is external work (W_external)

    def __init__(self, name: str, part, faces, elements, what: str):
        self.name, self.part = name, part
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        if (self.faces.ndim != 2 or self.faces.shape[0] == 0
                or self.faces.shape[1] not in (2, 4)):
            raise ValueError(f"{name}: no faces for {what} (faces must be (F, 4) or "
                             "(F, 2), F > 0)")
        self.elements = np.ascontiguousarray(elements, dtype=np.int64)
        self.nodes, self.local = face_rows(self.faces)
        if np.any(part.kin.m[self.nodes] <= 0.0):
            raise ValueError(f"{name}: {what} on nodes without mass")
        self._a = np.zeros((self.nodes.size, 3))  # the face nodes' accelerations [m/s^2]
        self._S = np.empty((self.faces.shape[1], 3))  # one face's area vectors (scratch)
        self.work = 0.0  # total [J]
        self._kick = 0.0  # over the last kick [J]

    @property
    def n_faces(self) -> int:
        return int(self.faces.shape[0])

    def after_kick(self, dt_kick: float) -> None:
        q = self.part.kin
        self._kick = set_work(self.nodes, q.m, self._a, q.v_mid, dt_kick)
        self.work += self._kick

    def external_work(self) -> float:
        return self._kick

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"work": self.work, "kick": self._kick}, {"a": self._a}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self.work = float(scalars["work"])
        self._kick = float(scalars["kick"])
        self._a[...] = arrays["a"]


class PressureLoad(FaceInteraction):
    """A pressure on faces of a solid mesh part (module docstring).

    Parameters
    ----------
    name : column prefix.
    part : a solid mesh part (``kin``, ``el.active``).
    faces : (F, 4) quadrilaterals or (F, 2) segments, outward node order;
        ``elements`` (F,) their elements.
    pressure : p [Pa], positive into the body.
    ramp_time, shape, curve : the time factor (:class:`~sphdyn.interactions.nodal.TimeFactor`).

    Columns: ``<name>_pressure`` [Pa] now, ``<name>_force_x|y|z`` the
    resultant now [N] (N/m in 2D), ``W_<name>`` its work so far [J]
    (external work).
    """

    def __init__(self, name: str, part, faces, elements, pressure: float,
                 ramp_time: float = 0.0, shape: str = "linear", curve=None):
        super().__init__(name, part, faces, elements, "a pressure")
        self.pressure = float(pressure)
        self.factor = TimeFactor(ramp_time, shape, curve)
        self.force = np.zeros((self.nodes.size, 3))  # nodal forces now [N]
        self._now = 0.0  # the pressure now [Pa]

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        q = self.part.kin
        self._now = self.pressure * self.factor(t)
        face_pressure_forces(q.x, self.faces, self.local, self.elements,
                             self.part.el.active, self._now, self._S, self.force)
        accelerate(self.nodes, q.m, self.force, self._a, a_out)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        out = {f"{self.name}_pressure": self._now, f"W_{self.name}": self.work}
        for k, c in enumerate("xyz"):
            out[f"{self.name}_force_{c}"] = float(f[k])
        return out

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        scalars, arrays = super().state()
        return {**scalars, "now": self._now}, {**arrays, "force": self.force}

    def restore(self, scalars: dict, arrays: dict) -> None:
        super().restore(scalars, arrays)
        self._now = float(scalars["now"])
        self.force[...] = arrays["force"]
