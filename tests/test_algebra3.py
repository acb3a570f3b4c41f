"""The 3x3 algebra of the hot loops (sphdyn.algebra3) against NumPy.

Random well-conditioned matrices (condition number below about 1e3 by
construction: identity plus a perturbation of norm < 1/2): the closed forms
and LAPACK agree to a few ulps of the entries, so 1e-12 relative to the
largest entry is round-off with a margin of ~100x, and a wrong sign or a
missing term (errors of order one) fails.
"""

import numpy as np
from numba import njit

from sphdyn.algebra3 import (det9, inverse3, inverse_sym3, load3, load9, matmul9,
                             tmatmul9)

RNG = np.random.default_rng(54)


def _matrices(n=50, symmetric=False):
    a = np.eye(3) + 0.5 * RNG.uniform(-1, 1, (n, 3, 3)) / 3
    return 0.5 * (a + a.transpose(0, 2, 1)) if symmetric else a


@njit(cache=False)
def _inverse_all(a, out, tol):
    dets = np.empty(a.shape[0])
    for i in range(a.shape[0]):
        a00, a01, a02, a10, a11, a12, a20, a21, a22 = load9(a, i)
        dets[i] = inverse3(a00, a01, a02, a10, a11, a12, a20, a21, a22, out[i], tol)
    return dets


@njit(cache=False)
def _det_all(a):
    return np.array([det9(a, i) for i in range(a.shape[0])])


@njit(cache=False)
def _sym_all(a, tol):
    out = np.empty((a.shape[0], 6))
    for i in range(a.shape[0]):
        q = inverse_sym3(a[i, 0, 0], a[i, 0, 1], a[i, 0, 2], a[i, 1, 1], a[i, 1, 2],
                         a[i, 2, 2], tol)
        for k in range(6):
            out[i, k] = q[k]
    return out


@njit(cache=False)
def _products(a, b):
    ab = np.empty((a.shape[0], 9))
    atb = np.empty((a.shape[0], 9))
    for i in range(a.shape[0]):
        p = matmul9(load9(a, i), load9(b, i))
        q = tmatmul9(load9(a, i), load9(b, i))
        for k in range(9):
            ab[i, k] = p[k]
            atb[i, k] = q[k]
    return ab, atb


@njit(cache=False)
def _rows(x):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = load3(x, i)
    return out


def test_general_inverse_and_determinant_are_numpys():
    a = _matrices()
    out = np.empty_like(a)
    dets = _inverse_all(a, out, 1e-12)
    np.testing.assert_allclose(out, np.linalg.inv(a), rtol=0, atol=1e-12 * np.abs(out).max())
    np.testing.assert_allclose(dets, np.linalg.det(a), rtol=1e-12)
    np.testing.assert_allclose(_det_all(a), np.linalg.det(a), rtol=1e-12)


def test_a_singular_matrix_gives_the_identity_and_a_zero_determinant():
    a = np.array([[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]]])  # rank 2
    out = np.full_like(a, np.nan)
    assert _inverse_all(a, out, 1e-12)[0] == 0.0
    assert np.array_equal(out[0], np.eye(3))
    sym = _sym_all(np.zeros((1, 3, 3)), 1e-6)[0]
    assert np.array_equal(sym, [1.0, 0.0, 0.0, 1.0, 0.0, 1.0])


def test_symmetric_inverse_is_numpys():
    a = _matrices(symmetric=True)
    q = _sym_all(a, 1e-6)
    inv = np.linalg.inv(a)
    upper = inv[:, [0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]
    np.testing.assert_allclose(q, upper, rtol=0, atol=1e-12 * np.abs(upper).max())


def test_products_and_loads_are_numpys():
    a, b = _matrices(), _matrices()
    ab, atb = _products(a, b)
    np.testing.assert_allclose(ab, (a @ b).reshape(-1, 9), rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(atb, (a.transpose(0, 2, 1) @ b).reshape(-1, 9), rtol=1e-14,
                               atol=1e-15)
    x = RNG.uniform(size=(7, 3))
    assert np.array_equal(_rows(x), x)
