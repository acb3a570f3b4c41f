r"""Bars embedded in solid elements: the nodes of a line part move with the elements they lie in.

The finite-element model of reinforced concrete that the sublayer coupling
is compared with (thesis 6.1, the I-girder's pure FEM model; LS-DYNA's
*CONSTRAINED_BEAM_IN_SOLID): the bar's elements lie freely in the concrete's
hexahedra (or quadrilaterals), and each bar node :math:`s` is a slave of the
element that contains it, at its parametric point :math:`\boldsymbol\xi_s`
(found once by :func:`locate`):

* motion: :math:`\mathbf x_s = \sum_a N_a(\boldsymbol\xi_s)\mathbf x_a`,
  :math:`\mathbf v_s = \sum_a N_a(\boldsymbol\xi_s)\mathbf v_a` after each
  kick (the kick skips the ``BC_SLAVE`` nodes);
* mass: the node's mass goes to the element's nodes, :math:`m_a \mathrel{+}=
  N_a m_s` (lumped);
* forces: the bar's internal force on the node and what the interactions
  give it go to the element's nodes, :math:`\mathbf F_a = N_a\mathbf F_s`
  (:func:`~.slaves.forces_to_masters`, as for the hybrid layer's
  particles). :math:`\sum_a N_a = 1`: momentum is conserved exactly.

The bar's volume overlaps the concrete's (perfect bond, no slip): the
composite's axial stiffness is :math:`E_c A_c + E_s A_s` with the concrete's
whole section, as in LS-DYNA. Beam rotations stay the beam's own.

The model and its tests: docs/theory.md, "Bars embedded in solid elements".
"""

from __future__ import annotations

import numpy as np

from ..geometry.shapes import shape_derivatives, shape_functions
from ..state import BC_FREE, BC_SLAVE
from .base import InteractionBase
from .slaves import follow_masters, pass_on

#: parametric tolerance of "inside an element" (the bar may end on a face)
_INSIDE = 1e-9


def locate(points, x, conn, dim: int, candidates: int = 8, iterations: int = 30):
    r"""The element containing each point and the point's parametric coordinates.

    Newton iterations on :math:`\mathbf x(\boldsymbol\xi) = \sum_a
    N_a(\boldsymbol\xi)\mathbf x_a` in the ``candidates`` elements with the
    nearest centroids; the first (nearest) element whose solution lies in
    :math:`[-1, 1]^d` (within :data:`_INSIDE`) is taken.

    Parameters
    ----------
    points : (n, 3) [m]; x : (N, 3) element nodes [m]; conn : (E, nen).

    Returns
    -------
    elem : (n,) int64, -1 for a point in no element; xi : (n, dim).
    """
    from scipy.spatial import cKDTree

    points = np.atleast_2d(np.asarray(points, float))
    centres = x[conn].mean(axis=1)
    k = min(candidates, conn.shape[0])
    near = cKDTree(centres).query(points, k=k)[1].reshape(points.shape[0], k)
    elem = np.full(points.shape[0], -1, dtype=np.int64)
    xi = np.zeros((points.shape[0], dim))
    for i, p in enumerate(points):
        for e in near[i]:
            xe = x[conn[e]][:, :dim]
            s = np.zeros(dim)
            for _ in range(iterations):
                r = shape_functions(dim, s)[0] @ xe - p[:dim]
                J = xe.T @ shape_derivatives(dim, s)[0]  # dx/dxi (dim, dim)
                step = np.linalg.solve(J, r)
                s = s - step
                if np.abs(step).max() < 1e-14:
                    break
            if np.abs(s).max() <= 1.0 + _INSIDE:
                elem[i], xi[i] = e, np.clip(s, -1.0, 1.0)
                break
    return elem, xi


class EmbeddedNodes(InteractionBase):
    """The nodes of ``line_part`` tied to the elements of ``solid_part`` they lie
    in (module docstring). History columns: ``F_<name>_x|y|z`` (the resultant
    force the bar passes to the concrete [N]) and ``embedded_<name>``."""

    def __init__(self, name: str, line_part, solid_part):
        q, s = line_part.kin, solid_part.nodes
        dim = solid_part.dim
        elem, xi = locate(q.x, s.x, solid_part.el.conn, dim)
        outside = np.flatnonzero(elem < 0)
        if outside.size:
            at = ", ".join(f"{c:.4g}" for c in q.x[outside[0]])
            raise ValueError(f"{name}: {outside.size} of the bar's {q.n} nodes lie in no "
                             f"element of mesh '{solid_part.name}' (the first at ({at}) m)")
        busy = np.flatnonzero(q.bc != BC_FREE)
        if busy.size:
            raise ValueError(f"{name}: bar nodes {busy[:5].tolist()} have boundary "
                             "conditions; an embedded node follows its element")
        self.name, self.part, self.solid = name, line_part, solid_part
        self.rows = np.arange(q.n, dtype=np.int64)
        self.elem = elem
        self.conn = np.ascontiguousarray(solid_part.el.conn, dtype=np.int64)
        self.N = np.ascontiguousarray(shape_functions(dim, xi))
        np.add.at(s.m, self.conn[elem].ravel(), (self.N * q.m[:, None]).ravel())
        q.bc[:] = BC_SLAVE
        self.force = np.zeros((q.n, 3))
        self.constrain(0.0, 0.0)

    def slave_map(self):
        """(slave table, slave rows (S,), master table, masters (S, nen), weights
        (S, nen)): each bar node follows its element's nodes with the shape
        functions (:mod:`sphdyn.mass_scaling` moves a slave's added mass so)."""
        return self.part.kin, self.rows, self.solid.nodes, self.conn[self.elem], self.N

    def constrain(self, t: float, dt: float) -> None:
        q, s = self.part.kin, self.solid.nodes
        follow_masters(self.rows, self.elem, self.N, self.conn, s.x, s.v, q.x, q.v)

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        pass_on(self.part.kin, self.solid.nodes, self.rows, self.elem, self.N, self.conn,
                a_out, self.force)

    def columns(self, t: float) -> dict[str, float]:
        f = self.force.sum(axis=0)
        return {f"F_{self.name}_x": float(f[0]), f"F_{self.name}_y": float(f[1]),
                f"F_{self.name}_z": float(f[2]), f"embedded_{self.name}": float(self.rows.size)}
