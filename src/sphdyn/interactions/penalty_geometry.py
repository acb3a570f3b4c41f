r"""Master surfaces of a solid mesh and the particle-face search of the SPH-FEM coupling.

* :func:`exterior_faces`: the boundary faces of a hex8 mesh (quadrilaterals
  that belong to one element only) or a quad4 mesh (edges of one element),
  with their nodes ordered so that the normal points out of the mesh;
* :func:`closest_point`: the point of a face closest to a particle (bilinear
  quadrilateral: Newton iterations in the face's parametric coordinates,
  clamped to the face; a straight segment in 2D), the face's normal there;
* :func:`candidate_pairs`: the particle-face pairs to test, from a uniform
  grid of the faces' bounding boxes (built again only when the Verlet skin
  is used up, :class:`~sphdyn.interactions.penalty_coupling.PenaltyCoupling`).

Face node order. A quadrilateral face (3D) has its nodes at the parametric
corners :math:`(\xi, \eta) = (-,-), (+,-), (+,+), (-,+)`, counter-clockwise
seen from outside, so :math:`\mathbf x_{,\xi}\times\mathbf x_{,\eta}` is the
outward normal. A segment (2D) runs from node 0 (:math:`\xi = -1`) to node
1 (:math:`\xi = +1`) counter-clockwise around the mesh, so the outward normal
is :math:`(t_y, -t_x)/|\mathbf t|` with :math:`\mathbf t = \mathbf x_1 -
\mathbf x_0`. Shape functions: :math:`N_a = (1 + \xi\xi_a)(1 + \eta\eta_a)/4`
(quadrilateral), :math:`(1 \pm \xi)/2` (segment).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

#: local faces of a hex8 element (VTK order), each counter-clockwise seen from outside
HEX8_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5],
                       [2, 3, 7, 6], [3, 0, 4, 7]], dtype=np.int64)
#: local edges of a quad4 element, counter-clockwise around it
QUAD4_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int64)

#: Newton iterations of the closest-point projection on a bilinear face
NEWTON_ITERATIONS = 8


def _local_faces(cells: np.ndarray) -> np.ndarray:
    """The local faces (hex8) or edges (quad4) of ``cells``' elements."""
    local = {8: HEX8_FACES, 4: QUAD4_EDGES}.get(cells.shape[1])
    if local is None:
        raise ValueError(f"exterior faces of hex8 or quad4 meshes, got {cells.shape[1]}-node "
                         "elements")
    return local


def face_twins(cells: np.ndarray) -> np.ndarray:
    """For each face slot ``s = e * n_local + f`` (element e, local face f) of a
    hex8 or quad4 mesh, the slot of the other element's face on the same
    nodes, -1 for a face of one element only, or -2 for a face held by more
    than two elements (not a valid mesh; never exterior, as the face count
    of the whole mesh has it): (E * n_local,) int64.

    Made once per mesh (a sort of the slots by their sorted node keys); the
    exterior faces of any subset of the elements then follow without a sort
    (:func:`exterior_faces`' ``active``), which erosion asks for after every
    event."""
    cells = np.asarray(cells, dtype=np.int64)
    local = _local_faces(cells)
    key = np.sort(cells[:, local].reshape(-1, local.shape[1]), axis=1)
    n = key.shape[0]
    twins = np.full(n, -1, dtype=np.int64)
    if n == 0:
        return twins
    order = np.lexsort(key.T[::-1])  # slots sorted by their keys
    k = key[order]
    start = np.flatnonzero(np.concatenate(([True], np.any(k[1:] != k[:-1], axis=1))))
    size = np.diff(np.append(start, n))
    pair = start[size == 2]
    twins[order[pair]] = order[pair + 1]
    twins[order[pair + 1]] = order[pair]
    twins[order[np.repeat(size > 2, size)]] = -2
    return twins


def exterior_faces(cells: np.ndarray, with_elements: bool = False, active=None,
                   twins=None):
    """Boundary faces of a mesh, oriented outward.

    Parameters
    ----------
    cells : (E, 8) hex8 or (E, 4) quad4 connectivity (VTK order).
    with_elements : also return the element of each face.
    active : optional (E,) flags: the exterior faces of the elements with a
        nonzero flag only (a face between a kept and a dropped element is
        exterior); the same faces, in the same order, as ``cells[active != 0]``
        gives, with elements numbered in ``cells``.
    twins : :func:`face_twins` of ``cells``, when made already.

    Returns
    -------
    faces : (F, 4) quadrilaterals (hex8) or (F, 2) segments (quad4), int64
        node indices in the order of the module docstring: the faces that
        belong to exactly one (kept) element, in element order then
        local-face order.
    elements : (F,) the element each face belongs to (``with_elements``).
    """
    cells = np.asarray(cells, dtype=np.int64)
    local = _local_faces(cells)
    n_local = local.shape[0]
    twins = face_twins(cells) if twins is None else twins
    kept = np.repeat(np.ones(cells.shape[0], dtype=bool) if active is None
                     else np.asarray(active) != 0, n_local)  # per face slot
    once = kept & ((twins == -1) | ((twins >= 0) & ~kept[np.maximum(twins, 0)]))
    slots = np.flatnonzero(once)
    out = np.ascontiguousarray(cells[slots // n_local][np.arange(slots.size)[:, None],
                                                        local[slots % n_local]])
    if with_elements:
        return out, slots // n_local
    return out


def face_nodes(faces: np.ndarray, n_nodes: int) -> np.ndarray:
    """The nodes (sorted, int64) of the faces (F, nf) of a mesh of ``n_nodes``
    nodes: ``numpy.unique(faces)`` by a mask, without a sort (after every
    erosion event)."""
    used = np.zeros(n_nodes, dtype=bool)
    used[faces.ravel()] = True
    return np.flatnonzero(used).astype(np.int64)


def on_nodes(faces: np.ndarray, nodes) -> np.ndarray:
    """Mask (F,) of the faces (F, nf) whose nodes all belong to the node set ``nodes``."""
    inside = np.zeros(int(faces.max()) + 1 if faces.size else 0, dtype=bool)
    nodes = np.asarray(nodes, dtype=np.int64)
    inside[nodes[nodes < inside.size]] = True
    return np.all(inside[faces], axis=1)


def faces_on_nodes(faces: np.ndarray, nodes) -> np.ndarray:
    """The faces (F, nf) whose nodes all belong to the node set ``nodes``."""
    return faces[on_nodes(faces, nodes)]


# --------------------------------------------------------------------------
# projection
# --------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def face_shapes(xi, eta, nf):
    """Shape functions (4-tuple) of a face at its parametric point: bilinear
    :math:`(1 + \\xi\\xi_a)(1 + \\eta\\eta_a)/4` (nf = 4) or
    :math:`(1 \\mp \\xi)/2` then two zeros (nf = 2)."""
    if nf == 2:
        return 0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0, 0.0
    return (0.25 * (1.0 - xi) * (1.0 - eta), 0.25 * (1.0 + xi) * (1.0 - eta),
            0.25 * (1.0 + xi) * (1.0 + eta), 0.25 * (1.0 - xi) * (1.0 + eta))


@njit(cache=True, error_model="numpy")
def _clamp(s):
    return -1.0 if s < -1.0 else (1.0 if s > 1.0 else s)


@njit(cache=True, error_model="numpy")
def closest_point(p, xn, face):
    r"""Closest point of one face to the point ``p`` and the face normal there.

    Quadrilateral (``face`` of 4 nodes): :math:`\mathbf x(\xi,\eta) = \mathbf a
    + \mathbf b\xi + \mathbf c\eta + \mathbf d\xi\eta` with
    :math:`\mathbf b = (-\mathbf x_0 + \mathbf x_1 + \mathbf x_2 - \mathbf x_3)/4`,
    :math:`\mathbf c = (-\mathbf x_0 - \mathbf x_1 + \mathbf x_2 + \mathbf x_3)/4`,
    :math:`\mathbf d = (\mathbf x_0 - \mathbf x_1 + \mathbf x_2 - \mathbf x_3)/4`.
    Newton's method on :math:`f = \tfrac12|\mathbf x(\xi,\eta) - \mathbf p|^2`
    (gradient :math:`\mathbf r\cdot\mathbf x_{,\xi}`, :math:`\mathbf r\cdot
    \mathbf x_{,\eta}`; Hessian :math:`\mathbf x_{,\alpha}\cdot\mathbf
    x_{,\beta} + \mathbf r\cdot\mathbf d` off the diagonal; Gauss-Newton
    where that is not positive definite), each iterate clamped to
    :math:`[-1, 1]^2`; when a coordinate ends on the boundary the other is
    minimised along that (straight) edge. Exact in one step for a flat
    parallelogram. Segment (2 nodes): :math:`\xi = 2(\mathbf p - \mathbf x_0)
    \cdot\mathbf t/|\mathbf t|^2 - 1`, clamped.

    Parameters
    ----------
    p : (3,) point [m]; xn : (N, 3) node positions [m]; face : (nf,) node ids.

    Returns
    -------
    xi, eta : parametric coordinates (eta = 0 for a segment);
    cx, cy, cz : the closest point [m];
    nx, ny, nz : unit outward normal at it (module docstring);
    clamped : True if the point is on the face's boundary by clamping.
    """
    if face.shape[0] == 2:
        a, b = face[0], face[1]
        t0 = xn[b, 0] - xn[a, 0]
        t1 = xn[b, 1] - xn[a, 1]
        ll = t0 * t0 + t1 * t1
        s = 2.0 * ((p[0] - xn[a, 0]) * t0 + (p[1] - xn[a, 1]) * t1) / ll - 1.0
        xi = _clamp(s)
        w = 0.5 * (1.0 + xi)
        cx = xn[a, 0] + w * t0
        cy = xn[a, 1] + w * t1
        inv = 1.0 / np.sqrt(ll)
        return xi, 0.0, cx, cy, 0.0, t1 * inv, -t0 * inv, 0.0, xi != s
    i0, i1, i2, i3 = face[0], face[1], face[2], face[3]
    # x(xi, eta) - p = a + b xi + c eta + d xi eta (scalars: no allocation per call)
    a0, b0, c0, d0 = _coefficients(xn[i0, 0], xn[i1, 0], xn[i2, 0], xn[i3, 0], p[0])
    a1, b1, c1, d1 = _coefficients(xn[i0, 1], xn[i1, 1], xn[i2, 1], xn[i3, 1], p[1])
    a2, b2, c2, d2 = _coefficients(xn[i0, 2], xn[i1, 2], xn[i2, 2], xn[i3, 2], p[2])
    xi = 0.0
    eta = 0.0
    clamped = False
    for _ in range(NEWTON_ITERATIONS):
        r0 = a0 + b0 * xi + c0 * eta + d0 * xi * eta
        r1 = a1 + b1 * xi + c1 * eta + d1 * xi * eta
        r2 = a2 + b2 * xi + c2 * eta + d2 * xi * eta
        e10, e11, e12 = b0 + d0 * eta, b1 + d1 * eta, b2 + d2 * eta
        e20, e21, e22 = c0 + d0 * xi, c1 + d1 * xi, c2 + d2 * xi
        g1 = r0 * e10 + r1 * e11 + r2 * e12
        g2 = r0 * e20 + r1 * e21 + r2 * e22
        h11 = e10 * e10 + e11 * e11 + e12 * e12
        h12 = e10 * e20 + e11 * e21 + e12 * e22
        h22 = e20 * e20 + e21 * e21 + e22 * e22
        rd = r0 * d0 + r1 * d1 + r2 * d2
        det = h11 * h22 - (h12 + rd) * (h12 + rd)
        if det > 0.0:
            h12 += rd
        else:  # Gauss-Newton
            det = h11 * h22 - h12 * h12
        s1 = xi - (h22 * g1 - h12 * g2) / det
        s2 = eta - (h11 * g2 - h12 * g1) / det
        xi_new = _clamp(s1)
        eta_new = _clamp(s2)
        clamped = xi_new != s1 or eta_new != s2
        done = abs(xi_new - xi) + abs(eta_new - eta) < 1e-14
        xi = xi_new
        eta = eta_new
        if done:
            break
    if clamped:  # minimise along the edge the point is on (edges are straight)
        if abs(xi) == 1.0 and abs(eta) < 1.0:
            e20, e21, e22 = c0 + d0 * xi, c1 + d1 * xi, c2 + d2 * xi
            num = ((a0 + b0 * xi + e20 * eta) * e20 + (a1 + b1 * xi + e21 * eta) * e21
                   + (a2 + b2 * xi + e22 * eta) * e22)
            eta = _clamp(eta - num / (e20 * e20 + e21 * e21 + e22 * e22))
        elif abs(eta) == 1.0 and abs(xi) < 1.0:
            e10, e11, e12 = b0 + d0 * eta, b1 + d1 * eta, b2 + d2 * eta
            num = ((a0 + c0 * eta + e10 * xi) * e10 + (a1 + c1 * eta + e11 * xi) * e11
                   + (a2 + c2 * eta + e12 * xi) * e12)
            xi = _clamp(xi - num / (e10 * e10 + e11 * e11 + e12 * e12))
    e10, e11, e12 = b0 + d0 * eta, b1 + d1 * eta, b2 + d2 * eta
    e20, e21, e22 = c0 + d0 * xi, c1 + d1 * xi, c2 + d2 * xi
    nx = e11 * e22 - e12 * e21
    ny = e12 * e20 - e10 * e22
    nz = e10 * e21 - e11 * e20
    inv = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
    cx = p[0] + a0 + b0 * xi + c0 * eta + d0 * xi * eta
    cy = p[1] + a1 + b1 * xi + c1 * eta + d1 * xi * eta
    cz = p[2] + a2 + b2 * xi + c2 * eta + d2 * xi * eta
    return xi, eta, cx, cy, cz, nx * inv, ny * inv, nz * inv, clamped


@njit(cache=True, error_model="numpy")
def face_point(xn, face, xi, eta):
    r"""Point and unit outward normal of a face at its parametric point.

    Quadrilateral: :math:`\mathbf x(\xi,\eta) = \sum_a N_a \mathbf x_a`,
    :math:`\mathbf n \parallel \mathbf x_{,\xi}\times\mathbf x_{,\eta}`
    (the normal of :func:`closest_point`); segment (2D): :math:`\mathbf n =
    (t_y, -t_x)/|\mathbf t|` with :math:`\mathbf t = \mathbf x_1 - \mathbf x_0`.
    ``xn`` (N, 3) [m]; ``face`` (nf,) node ids. Returns ``cx, cy, cz, nx, ny, nz``.
    """
    if face.shape[0] == 2:
        a, b = face[0], face[1]
        t0 = xn[b, 0] - xn[a, 0]
        t1 = xn[b, 1] - xn[a, 1]
        w = 0.5 * (1.0 + xi)
        inv = 1.0 / np.sqrt(t0 * t0 + t1 * t1)
        return xn[a, 0] + w * t0, xn[a, 1] + w * t1, 0.0, t1 * inv, -t0 * inv, 0.0
    i0, i1, i2, i3 = face[0], face[1], face[2], face[3]
    a0, b0, c0, d0 = _coefficients(xn[i0, 0], xn[i1, 0], xn[i2, 0], xn[i3, 0], 0.0)
    a1, b1, c1, d1 = _coefficients(xn[i0, 1], xn[i1, 1], xn[i2, 1], xn[i3, 1], 0.0)
    a2, b2, c2, d2 = _coefficients(xn[i0, 2], xn[i1, 2], xn[i2, 2], xn[i3, 2], 0.0)
    e10, e11, e12 = b0 + d0 * eta, b1 + d1 * eta, b2 + d2 * eta
    e20, e21, e22 = c0 + d0 * xi, c1 + d1 * xi, c2 + d2 * xi
    nx = e11 * e22 - e12 * e21
    ny = e12 * e20 - e10 * e22
    nz = e10 * e21 - e11 * e20
    inv = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
    return (a0 + b0 * xi + c0 * eta + d0 * xi * eta, a1 + b1 * xi + c1 * eta + d1 * xi * eta,
            a2 + b2 * xi + c2 * eta + d2 * xi * eta, nx * inv, ny * inv, nz * inv)


@njit(cache=True, error_model="numpy")
def _coefficients(x0, x1, x2, x3, pk):
    """One component of a, b, c, d of the bilinear face, ``a`` relative to ``pk``."""
    return (0.25 * (x0 + x1 + x2 + x3) - pk, 0.25 * (-x0 + x1 + x2 - x3),
            0.25 * (-x0 - x1 + x2 + x3), 0.25 * (x0 - x1 + x2 - x3))


# --------------------------------------------------------------------------
# candidate search
# --------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _cell(xa, lo, inv_cs, n):
    c = int(math.floor((xa - lo) * inv_cs))
    return 0 if c < 0 else (n - 1 if c > n - 1 else c)


@njit(cache=True, error_model="numpy")
def _face_boxes(xn, faces, reach):
    """Face bounding boxes (F, 3) lo and hi [m], grown by ``reach`` on every side."""
    nf = faces.shape[0]
    lo = np.empty((nf, 3))
    hi = np.empty((nf, 3))
    for f in range(nf):
        for k in range(3):
            mn = xn[faces[f, 0], k]
            mx = mn
            for j in range(1, faces.shape[1]):
                v = xn[faces[f, j], k]
                mn = min(mn, v)
                mx = max(mx, v)
            lo[f, k] = mn - reach
            hi[f, k] = mx + reach
    return lo, hi


@njit(cache=True, error_model="numpy", parallel=True)
def _pairs(xp, blo, bhi, order, cell_start, glo, inv_cs, nc, dim, offsets, idx, fill):
    """Count (``fill`` False) or store the faces whose box holds each particle.

    Gather form: row ``i`` is written by particle ``i`` only. Rows list the
    faces in grid order (not sorted); the force kernel breaks ties by face
    index, so the order does not matter.
    """
    n = xp.shape[0]
    for i in prange(n):
        cx = _cell(xp[i, 0], glo[0], inv_cs, nc[0])
        cy = _cell(xp[i, 1], glo[1], inv_cs, nc[1])
        cz = _cell(xp[i, 2], glo[2], inv_cs, nc[2]) if dim == 3 else 0
        k = offsets[i] if fill else 0
        for z in range(max(cz - 1, 0), min(cz + 2, nc[2])):
            for y in range(max(cy - 1, 0), min(cy + 2, nc[1])):
                for x in range(max(cx - 1, 0), min(cx + 2, nc[0])):
                    c = x + nc[0] * (y + nc[1] * z)
                    for s in range(cell_start[c], cell_start[c + 1]):
                        f = order[s]
                        inside = True
                        for a in range(dim):
                            if xp[i, a] < blo[f, a] or xp[i, a] > bhi[f, a]:
                                inside = False
                        if inside:
                            if fill:
                                idx[k] = f
                            k += 1
        if not fill:
            offsets[i + 1] = k


def candidate_pairs(xp: np.ndarray, xn: np.ndarray, faces: np.ndarray, reach: float,
                    dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Faces whose bounding box grown by ``reach`` [m] holds each particle (CSR).

    The faces are binned by the centre of their grown boxes on a uniform grid
    whose cell is at least the largest half-extent of a grown box, so a box
    holding a particle has its centre within one cell of the particle's cell
    (a 3^d stencil). Cost O(F + N 3^d n_per_cell); run at a Verlet rebuild.

    Parameters
    ----------
    xp : (N, 3) particle positions [m]; xn : (M, 3) node positions [m];
    faces : (F, nf) node ids; reach : search distance [m]; dim : 2 or 3.

    Returns
    -------
    offsets : (N + 1,) int64; idx : (nnz,) int64 face ids, row ``i`` is
    ``idx[offsets[i]:offsets[i + 1]]``.
    """
    n = xp.shape[0]
    offsets = np.zeros(n + 1, dtype=np.int64)
    if n == 0 or faces.shape[0] == 0:
        return offsets, np.zeros(0, dtype=np.int64)
    blo, bhi = _face_boxes(xn, faces, reach)
    centre = 0.5 * (blo + bhi)
    half = 0.5 * (bhi - blo)
    cs = float(half[:, :dim].max()) * (1.0 + 1e-6)
    glo = centre.min(axis=0)
    ext = centre.max(axis=0) - glo
    cap = 4.0 * faces.shape[0] + 64.0
    while True:
        nc = np.array([int(ext[a] / cs) + 1 if a < dim else 1 for a in range(3)], dtype=np.int64)
        if float(np.prod(nc.astype(float))) <= cap:
            break
        cs *= 1.5
    inv_cs = 1.0 / cs
    cell = np.zeros(faces.shape[0], dtype=np.int64)
    for a in range(dim):
        ca = np.clip(np.floor((centre[:, a] - glo[a]) * inv_cs).astype(np.int64), 0, nc[a] - 1)
        cell += ca * int(np.prod(nc[:a]))
    order = np.argsort(cell, kind="stable").astype(np.int64)
    cell_start = np.zeros(int(np.prod(nc)) + 1, dtype=np.int64)
    np.add.at(cell_start, cell + 1, 1)
    cell_start = np.cumsum(cell_start)
    dummy = np.zeros(0, dtype=np.int64)
    _pairs(xp, blo, bhi, order, cell_start, glo, inv_cs, nc, dim, offsets, dummy, False)
    offsets[1:] = np.cumsum(offsets[1:])
    idx = np.empty(offsets[-1], dtype=np.int64)
    _pairs(xp, blo, bhi, order, cell_start, glo, inv_cs, nc, dim, offsets, idx, True)
    return offsets, idx


# --------------------------------------------------------------------------
# anchors of tied particles
# --------------------------------------------------------------------------
def face_anchors(xp: np.ndarray, size: np.ndarray, xn: np.ndarray, faces: np.ndarray,
                 factor: float, dim: int):
    r"""The points of the faces that particles near them are tied to.

    A particle :math:`p` is anchored when its closest point on the faces
    (:func:`closest_point`; the nearest face, ties to the lower index) lies
    inside a face (not clamped to its boundary, or clamped by less than
    :math:`10^{-6}` sizes) and its normal distance is at most ``factor``
    times its size. Its anchor is :math:`(f, \xi, \eta, g_0)`: the face, the
    parametric point and the signed normal offset, so that
    :math:`\mathbf x_p = \sum_a N_a(\xi,\eta)\mathbf x_a + g_0\mathbf n`
    at the start.

    Parameters
    ----------
    xp : (N, 3) particle positions [m]; size : (N,) particle sizes [m].
    xn : (M, 3) node positions [m]; faces : (F, nf) faces (module docstring).
    factor : tie distance in particle sizes (0: none tied).
    dim : 2 or 3.

    Returns
    -------
    rows (T,) int64 particle indices, face (T,) int64, xi, eta, offset (T,)
    float64 (offset in m).
    """
    rows, faces_, xis, etas, offs = [], [], [], [], []
    if factor > 0.0 and xp.shape[0]:
        offsets, cand = candidate_pairs(xp, xn, faces, factor * float(size.max()), dim)
        for i in range(xp.shape[0]):
            best = None
            for f in cand[offsets[i]:offsets[i + 1]]:
                xi, eta, cx, cy, cz, nx, ny, nz, clamped = closest_point(xp[i], xn, faces[f])
                r = xp[i] - np.array([cx, cy, cz])
                d2 = float(r @ r)
                if best is None or d2 < best[0]:
                    best = (d2, f, xi, eta, float(r @ np.array([nx, ny, nz])), clamped)
            if best is None:
                continue
            d2, f, xi, eta, rn, clamped = best
            lateral = np.sqrt(max(d2 - rn * rn, 0.0))
            if (not clamped or lateral <= 1e-6 * size[i]) and abs(rn) <= factor * size[i]:
                rows.append(i)
                faces_.append(f)
                xis.append(xi)
                etas.append(eta)
                offs.append(rn)
    return (np.asarray(rows, dtype=np.int64), np.asarray(faces_, dtype=np.int64),
            np.asarray(xis, dtype=np.float64), np.asarray(etas, dtype=np.float64),
            np.asarray(offs, dtype=np.float64))
