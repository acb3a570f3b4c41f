r"""Coupled SPH-FEM models from one mesh: chosen elements become particles.

The thesis builds its coupled models from a finite-element mesh (chapter 4,
"Coupling SPH and FEM"): the elements of the region that will fragment are
replaced by SPH particles, one per element, and the rest of the mesh stays
finite elements; the two are then tied by a contact (penalty) interface,
:class:`sphdyn.interactions.penalty_coupling.PenaltyCoupling`.

A particle made from element :math:`e` sits at the element's centroid and
carries its volume,

.. math::
    V_e = \int_{\Omega_e} d\Omega = \int_{[-1,1]^d} \det J\, d\boldsymbol\xi,
    \qquad
    \mathbf x_e = \frac1{V_e}\int_{[-1,1]^d} \mathbf x(\boldsymbol\xi)\,
    \det J\, d\boldsymbol\xi,

with the isoparametric map :math:`\mathbf x(\boldsymbol\xi) = \sum_a
N_a(\boldsymbol\xi)\mathbf x_a` (trilinear hex8, bilinear quad4). The
integrands are polynomials of degree at most 3 in each natural coordinate
(:math:`\mathbf x` is of degree 1, :math:`\det J` of degree 2), so the
:math:`2^d` Gauss points integrate both exactly. The particle's mass is the
element's, :math:`\rho V_e`, when the particle gets the element's material.

The model and its tests: docs/theory.md, "SPH-FEM coupling by a hybrid transition layer".
"""

from __future__ import annotations

import numpy as np

from .mesh import MESH_KINDS
from .shapes import gauss_derivatives, gauss_points, shape_derivatives, shape_functions

__all__ = ["element_centroids", "elements_to_particles", "hybrid_points"]


def element_centroids(points, cells, kind: str) -> tuple[np.ndarray, np.ndarray]:
    r"""Volume-weighted centroids and volumes of hex8 or quad4 elements.

    :math:`V_e = \sum_g \det J(\boldsymbol\xi_g)` and
    :math:`\mathbf x_e = \sum_g \mathbf x(\boldsymbol\xi_g) \det J(\boldsymbol\xi_g) / V_e`
    over the :math:`2^d` Gauss points :math:`\pm 1/\sqrt 3` (unit weights;
    exact, see the module docstring).

    Parameters
    ----------
    points : (N, 3) node positions [m] (z = 0 in 2D).
    cells : (E, nen) connectivity, VTK node order (:mod:`sphdyn.geometry.mesh`).
    kind : ``"hex8"`` or ``"quad4"``.

    Returns
    -------
    centroids : (E, 3) [m]; volumes : (E,) [m^3] (hex8) or [m^2] (quad4,
    per unit depth).
    """
    if kind not in ("hex8", "quad4"):
        raise ValueError(f"elements_to_particles needs hex8 or quad4 elements, got {kind!r}")
    d = MESH_KINDS[kind][1]
    N = shape_functions(d, gauss_points(d))                 # (G, nen)
    dN = gauss_derivatives(d)                               # (G, nen, d)
    x = np.asarray(points, dtype=np.float64)[np.asarray(cells, dtype=np.int64)]  # (E, nen, 3)
    jac = np.einsum("eai,gaj->egij", x[:, :, :d], dN)       # (E, G, d, d)
    det = np.linalg.det(jac)                                # (E, G)
    vol = det.sum(axis=1)
    xq = np.einsum("ga,eai->egi", N, x)                     # (E, G, 3) Gauss points in space
    centroids = np.einsum("eg,egi->ei", det, xq) / vol[:, None]
    return centroids, vol


def elements_to_particles(points, cells, kind: str, element_mask):
    """Turn the selected elements into particles; keep the rest as a mesh.

    Parameters
    ----------
    points : (N, 3) node positions [m].
    cells : (E, nen) connectivity (hex8 or quad4, VTK node order).
    kind : ``"hex8"`` or ``"quad4"``.
    element_mask : (E,) bool, or an index array of the elements to convert.

    Returns
    -------
    centroids : (k, 3) [m], the particles' positions (the elements' centroids,
        :func:`element_centroids`), in element order.
    volumes : (k,) [m^dim], the particles' volumes (mass = density times it).
    remaining_cells : (E - k, nen) int64, the other elements in their order,
        renumbered onto the kept nodes.
    kept_node_index : (n_kept,) int64, ascending: the old index of every kept
        node, so the remaining mesh's points are ``points[kept_node_index]``.
        Nodes used only by converted elements are dropped.
    """
    cells = np.asarray(cells, dtype=np.int64)
    mask = np.asarray(element_mask)
    if mask.dtype != np.bool_:
        sel = np.zeros(cells.shape[0], dtype=bool)
        sel[mask.astype(np.int64)] = True
        mask = sel
    if mask.shape != (cells.shape[0],):
        raise ValueError(f"element_mask must have shape ({cells.shape[0]},), got {mask.shape}")
    centroids, volumes = element_centroids(points, cells[mask], kind)
    rest = cells[~mask]
    kept = np.unique(rest)
    new_index = np.full(np.asarray(points).shape[0], -1, dtype=np.int64)
    new_index[kept] = np.arange(kept.size)
    return centroids, volumes, new_index[rest], kept


#: local faces (hex8) and edges (quad4) of an element, for face sharing
_LOCAL_FACES = {"hex8": np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5],
                                  [2, 3, 7, 6], [3, 0, 4, 7]]),
                "quad4": np.array([[0, 1], [1, 2], [2, 3], [3, 0]])}


def hybrid_points(points, cells, kind: str, element_mask, one_point: bool):
    r"""Integration points of the hybrid layer: the elements next to converted ones.

    The thesis's transition layer (ch. 4): "the first neighbouring FEM
    elements were used as the hybrid ones". An element not in
    ``element_mask`` is hybrid when it shares a face (hex8) or an edge
    (quad4) with one that is. Its points are the centre
    :math:`\boldsymbol\xi = 0` with the element's volume
    (:func:`element_centroids`; ``one_point``)
    or the :math:`2^d` Gauss points :math:`\pm 1/\sqrt 3` with
    :math:`\det\mathsf J(\boldsymbol\xi_g)` each (unit weights; they sum
    to the volume exactly).

    Parameters
    ----------
    points : (N, 3) [m]; cells : (E, nen); kind : ``"hex8"`` or ``"quad4"``.
    element_mask : (E,) bool, the converted elements.
    one_point : one point per element, else 2^d.

    Returns
    -------
    elements : (H,) int64, the hybrid points' elements in the numbering of
        the **remaining** cells (``cells[~element_mask]``); x : (H, 3) [m];
        vol : (H,) [m^d]; xi : (H, d) natural coordinates.
    """
    d = 3 if kind == "hex8" else 2
    cells = np.asarray(cells, dtype=np.int64)
    mask = np.asarray(element_mask, dtype=bool)
    local = _LOCAL_FACES[kind]
    keys = np.sort(cells[:, local], axis=2)                     # (E, nface, nf)
    conv = {tuple(k) for k in keys[mask].reshape(-1, local.shape[1])}
    rest = np.flatnonzero(~mask)
    hyb = np.array([r for r in range(rest.size)
                    if any(tuple(k) in conv for k in keys[rest[r]])], dtype=np.int64)
    xi = np.zeros((1, d)) if one_point else gauss_points(d)     # (G, d)
    G = xi.shape[0]
    x = np.asarray(points, dtype=np.float64)[cells[rest[hyb]]]  # (H_el, nen, 3)
    N = shape_functions(d, xi)                                  # (G, nen)
    dN = shape_derivatives(d, xi)                               # (G, nen, d)
    det = np.linalg.det(np.einsum("eai,gaj->egij", x[:, :, :d], dN))  # (H_el, G)
    vol = element_centroids(points, cells[rest[hyb]], kind)[1][:, None] if one_point else det
    xq = np.einsum("ga,eai->egi", N, x)
    return (np.repeat(hyb, G), xq.reshape(-1, 3), vol.reshape(-1),
            np.tile(xi, (hyb.size, 1)))
