r"""The 3x3 algebra of the hot loops, in registers: one home for every kernel.

A row's vector or matrix is loaded into scalars (:func:`load3`,
:func:`load9`: the prologue every SPH and FEM row shares), multiplied as
9-tuples in row-major order (:func:`matmul9`, :func:`tmatmul9`), and
inverted (:func:`inverse3`, general, by cofactors along the first column;
:func:`inverse_sym3`, symmetric, by cofactors along the first row). The
functions are inlined into their callers (``inline="always"``), so a
kernel that uses them compiles to the same instructions as with the
expressions written out: same operations in the same order, same bits.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def load3(a, i):
    """Row ``i`` of an (N, 3) array as 3 scalars."""
    return a[i, 0], a[i, 1], a[i, 2]


@njit(cache=True, error_model="numpy", inline="always")
def load9(t, i):
    """Matrix ``i`` of an (N, 3, 3) array as 9 scalars, row-major."""
    return (t[i, 0, 0], t[i, 0, 1], t[i, 0, 2], t[i, 1, 0], t[i, 1, 1], t[i, 1, 2],
            t[i, 2, 0], t[i, 2, 1], t[i, 2, 2])


@njit(cache=True, error_model="numpy", inline="always")
def matmul9(a, b):
    """:math:`a b` of two row-major 9-tuples."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6],
            a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
            a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
            a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6],
            a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@njit(cache=True, error_model="numpy", inline="always")
def tmatmul9(a, b):
    """:math:`a^T b` of two row-major 9-tuples."""
    return (a[0] * b[0] + a[3] * b[3] + a[6] * b[6],
            a[0] * b[1] + a[3] * b[4] + a[6] * b[7],
            a[0] * b[2] + a[3] * b[5] + a[6] * b[8],
            a[1] * b[0] + a[4] * b[3] + a[7] * b[6],
            a[1] * b[1] + a[4] * b[4] + a[7] * b[7],
            a[1] * b[2] + a[4] * b[5] + a[7] * b[8],
            a[2] * b[0] + a[5] * b[3] + a[8] * b[6],
            a[2] * b[1] + a[5] * b[4] + a[8] * b[7],
            a[2] * b[2] + a[5] * b[5] + a[8] * b[8])


@njit(cache=True, error_model="numpy", inline="always")
def det9(F, i):
    r"""Determinant of ``F[i]`` (F (N, 3, 3)), expanded along the first row."""
    return (F[i, 0, 0] * (F[i, 1, 1] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 1])
            - F[i, 0, 1] * (F[i, 1, 0] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 0])
            + F[i, 0, 2] * (F[i, 1, 0] * F[i, 2, 1] - F[i, 1, 1] * F[i, 2, 0]))


@njit(cache=True, error_model="numpy", inline="always")
def inverse3(a00, a01, a02, a10, a11, a12, a20, a21, a22, out, tol):
    r"""Inverse of the 3x3 matrix :math:`a` into ``out`` (3, 3), its
    determinant returned (cofactors :math:`c`, expanded along the first
    column); the identity and 0 if :math:`|\det a| <` ``tol``."""
    c00 = a11 * a22 - a12 * a21
    c01 = a02 * a21 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a10 * c01 + a20 * c02
    if abs(det) < tol:
        for r in range(3):
            for s in range(3):
                out[r, s] = 1.0 if r == s else 0.0
        return 0.0
    inv = 1.0 / det
    out[0, 0] = c00 * inv
    out[0, 1] = c01 * inv
    out[0, 2] = c02 * inv
    out[1, 0] = (a12 * a20 - a10 * a22) * inv
    out[1, 1] = (a00 * a22 - a02 * a20) * inv
    out[1, 2] = (a02 * a10 - a00 * a12) * inv
    out[2, 0] = (a10 * a21 - a11 * a20) * inv
    out[2, 1] = (a01 * a20 - a00 * a21) * inv
    out[2, 2] = (a00 * a11 - a01 * a10) * inv
    return det


@njit(cache=True, error_model="numpy", inline="always")
def inverse_sym3(m00, m01, m02, m11, m12, m22, tol):
    r"""Upper triangle ``(q00, q01, q02, q11, q12, q22)`` of the inverse of
    the symmetric 3x3 matrix :math:`m` (given by its upper triangle;
    cofactors along the first row); the identity if :math:`|\det m| \le`
    ``tol``."""
    q00 = q11 = q22 = 1.0
    q01 = q02 = q12 = 0.0
    c00 = m11 * m22 - m12 * m12
    c01 = m02 * m12 - m01 * m22
    c02 = m01 * m12 - m02 * m11
    det = m00 * c00 + m01 * c01 + m02 * c02
    if abs(det) > tol:
        inv = 1.0 / det
        q00 = c00 * inv
        q01 = c01 * inv
        q02 = c02 * inv
        q11 = (m00 * m22 - m02 * m02) * inv
        q12 = (m02 * m01 - m00 * m12) * inv
        q22 = (m00 * m11 - m01 * m01) * inv
    return q00, q01, q02, q11, q12, q22
