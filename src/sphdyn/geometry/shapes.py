r"""Shape-function tables of the 8-node hexahedron and the 4-node quadrilateral.

Node order is VTK's (= LS-DYNA's): the corners in the isoparametric cube
:math:`\xi, \eta, \zeta \in [-1, 1]` are (-,-,-), (+,-,-), (+,+,-), (-,+,-),
then the same four with :math:`\zeta = +1`; the quadrilateral is the first
four with :math:`\zeta` dropped. Shape functions
:math:`N_I = \prod_k (1 + \xi_k \xi_{kI}) / 2^d`.

Everything here is computed once, in NumPy, from these definitions: the
mesh checks of :mod:`.mesh` and the centroids of :mod:`.convert` use the
shape functions, the Numba kernels of :mod:`sphdyn.parts.fem.solid` read the
tables.

* :func:`volume_table`: the element volume of a trilinear hexahedron is a
  cubic form of the nodal coordinates,
  :math:`V = \sum_{IJK} C_{IJK}\, x_I\, y_J\, z_K`, with
  :math:`C_{IJK} = \int \det[\partial N_I/\partial\boldsymbol\xi,
  \partial N_J/\partial\boldsymbol\xi, \partial N_K/\partial\boldsymbol\xi]\,
  d\boldsymbol\xi` (exact with 2x2x2 Gauss points). C is fully antisymmetric
  with 144 non-zero entries of :math:`\pm 1/12`, so
  :math:`\partial V/\partial x_I = \sum_{JK} C_{IJK}\, y_J z_K` (and cyclic for
  y, z) is 18 terms per node, 6 products when grouped by J: the "uniform
  strain" gradient of Flanagan &
  Belytschko (1981, IJNME 17, eq. 79), :math:`b_{iI} = \frac1V \partial V/\partial
  x_{iI}`, exact for any hexahedron, with
  :math:`V = \tfrac13 \sum_I \mathbf x_I\cdot \partial V/\partial\mathbf x_I`
  (Euler's theorem for a homogeneous cubic). In 2D the area is the quadratic
  form :math:`A = \sum_{IJ} C_{IJ} x_I y_J`, :math:`A = \tfrac12 \sum_I
  \mathbf x_I \cdot \partial A/\partial \mathbf x_I`.
* :func:`hourglass_vectors`: the base vectors
  :math:`\Gamma_{\alpha I}` of the hourglass modes (products
  :math:`\eta\zeta, \zeta\xi, \xi\eta, \xi\eta\zeta` of the corner signs;
  :math:`\xi\eta` in 2D), orthogonal to the rigid and linear fields
  (Flanagan & Belytschko 1981, Table 1).
* :func:`gauss_derivatives`: :math:`\partial N_I/\partial \boldsymbol\xi` at the
  2x2x2 (2x2) Gauss points, for the selective-reduced element.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

#: corner signs (xi, eta, zeta) in VTK order
HEX_SIGNS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
QUAD_SIGNS = HEX_SIGNS[:4, :2].copy()

def corner_signs(dim: int) -> np.ndarray:
    """Corner signs (nen, dim) of the hexahedron (dim 3) or quadrilateral (dim 2)."""
    return HEX_SIGNS if dim == 3 else QUAD_SIGNS


def shape_functions(dim: int, xi: np.ndarray) -> np.ndarray:
    r""":math:`N_I = \prod_k (1 + \xi_k \xi_{kI}) / 2^d` (P, nen) at the points ``xi`` (P, dim)."""
    s = corner_signs(dim)
    return np.prod(1.0 + s[None, :, :] * np.atleast_2d(xi)[:, None, :], axis=2) / 2 ** dim


def shape_derivatives(dim: int, xi: np.ndarray) -> np.ndarray:
    r""":math:`\partial N_I/\partial \xi_k` (P, nen, dim) at the points ``xi`` (P, dim)
    (Hughes, *The Finite Element Method*, 2000, sec. 3.5)."""
    s = corner_signs(dim)
    f = 1.0 + s[None, :, :] * np.atleast_2d(xi)[:, None, :]  # (P, nen, dim) factors
    out = np.empty(f.shape)
    for k in range(dim):
        out[:, :, k] = s[None, :, k] * np.prod(np.delete(f, k, axis=2), axis=2)
    return out / 2 ** dim


def gauss_points(dim: int) -> np.ndarray:
    """The 2^dim Gauss points (+-1/sqrt 3) in node order; weights are 1."""
    g = 1.0 / np.sqrt(3.0)
    return corner_signs(dim) * g


@functools.cache
def gauss_derivatives(dim: int) -> np.ndarray:
    r""":math:`\partial N_I/\partial \boldsymbol\xi` (ngp, nen, dim) at the Gauss points."""
    return shape_derivatives(dim, gauss_points(dim))


@functools.cache
def volume_coefficients(dim: int) -> np.ndarray:
    r"""The dense form coefficients: C (8, 8, 8) of :math:`V = C_{IJK} x_I y_J z_K`
    (dim 3) or C (4, 4) of :math:`A = C_{IJ} x_I y_J` (dim 2)."""
    nen = 2 ** dim
    C = np.zeros((nen,) * dim)
    for d in gauss_derivatives(dim):  # exact: the integrand is of degree <= 2 per variable
        for idx in itertools.product(range(nen), repeat=dim):
            C[idx] += np.linalg.det(d[list(idx)].T)
    C[np.abs(C) < 1e-12] = 0.0
    return C


@functools.cache
def volume_table(dim: int) -> np.ndarray:
    r"""Sparse form of :func:`volume_coefficients` for the kernels.

    dim 3: int64 (8, 6, 5) rows ``(J, P1, P2, M1, M2)``: the 18 terms of
    :math:`\partial V/\partial x_I` grouped by J (six per node, each with two
    or four K of balanced signs), so that

    .. math:: \partial V/\partial x_I = \tfrac1{12} \sum_J y_J\,
              (z_{P1} + z_{P2} - z_{M1} - z_{M2})

    and cyclically :math:`\partial V/\partial y_I` with :math:`z_J (x_P - x_M)`,
    :math:`\partial V/\partial z_I` with :math:`x_J (y_P - y_M)`: 18 products
    per node instead of 54. A missing second pair points at row 8, a row of
    zeros the kernels keep after the eight nodes.
    dim 2: int64 (4, 2, 2) rows ``(J, sign)`` with
    :math:`\partial A/\partial x_I = \tfrac12 \sum_k s_k y_{J_k}`,
    :math:`\partial A/\partial y_I = -\tfrac12 \sum_k s_k x_{J_k}`.
    """
    C = volume_coefficients(dim)
    nen = 2 ** dim
    if dim == 2:
        rows = [[[j, int(round(2.0 * C[i, j]))] for j in np.flatnonzero(C[i])]
                for i in range(nen)]
        return np.array(rows, dtype=np.int64)
    table = np.full((nen, 6, 5), nen, dtype=np.int64)  # nen: the zero row
    for i in range(nen):
        js = sorted({int(j) for j, _ in np.argwhere(C[i] != 0.0)})
        assert len(js) == 6, "six neighbours J per node"
        for g, j in enumerate(js):
            ks = np.flatnonzero(C[i, j])
            plus = [int(k) for k in ks if C[i, j, k] > 0]
            minus = [int(k) for k in ks if C[i, j, k] < 0]
            assert len(plus) == len(minus) and np.allclose(np.abs(C[i, j, ks]), 1 / 12)
            table[i, g, 0] = j
            table[i, g, 1:1 + len(plus)] = plus
            table[i, g, 3:3 + len(minus)] = minus
    return table


@functools.cache
def hourglass_vectors(dim: int) -> np.ndarray:
    r"""Hourglass base vectors :math:`\Gamma_{\alpha I}` (modes, nen): 4 in 3D, 1 in 2D."""
    s = corner_signs(dim)
    if dim == 2:
        return (s[:, 0] * s[:, 1])[None, :].copy()
    return np.array([s[:, 1] * s[:, 2], s[:, 2] * s[:, 0], s[:, 0] * s[:, 1],
                     s[:, 0] * s[:, 1] * s[:, 2]])
