r"""Element loads onto nodes, race-free: the node-to-element list and the gather.

Element kernels write each element's nodal loads into its own row of
``fe`` (E, nen, k); :func:`gather_loads` then sums them per node through the
node-to-element list of :func:`node_element_list`, so no two threads write
the same memory (the gather form of the particle passes).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


def node_element_list(conn: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """CSR list (offsets (N+1,), slots) of the element slots ``e * nen + I`` of each
    node, in element order."""
    flat = np.asarray(conn, dtype=np.int64).ravel()
    order = np.argsort(flat, kind="stable")
    counts = np.bincount(flat, minlength=n_nodes)
    offsets = np.zeros(n_nodes + 1, np.int64)
    np.cumsum(counts, out=offsets[1:])
    return offsets, order.astype(np.int64)


@njit(cache=True, error_model="numpy", parallel=True)
def gather_loads(fe, col, offsets, slots, m, a):
    r"""Node accelerations :math:`\mathbf a_n = \sum_{(e, I)\ni n} \mathbf f_{eI} / m_n`.

    ``fe`` (E, nen, k) element nodal loads (C-contiguous); the three columns ``col:col+3``
    are gathered (forces [N] with masses [kg]; for beams also moments [N m]
    with rotary inertias [kg m^2]); ``offsets`` (N+1,) and ``slots`` the
    node-to-element list (:func:`node_element_list`); ``m`` (N,); ``a``
    (N, 3) out (0 where m = 0).
    """
    # slot s = e * nen + I is row s of fe seen as (E * nen, k): no integer
    # division per slot (it cost more than the loads)
    width = fe.shape[2]
    flat = fe.reshape(fe.shape[0] * fe.shape[1] * width)
    for n in prange(a.shape[0]):
        f0 = 0.0
        f1 = 0.0
        f2 = 0.0
        for k in range(offsets[n], offsets[n + 1]):
            at = slots[k] * width + col
            f0 += flat[at]
            f1 += flat[at + 1]
            f2 += flat[at + 2]
        inv = 1.0 / m[n] if m[n] > 0.0 else 0.0
        a[n, 0] = f0 * inv
        a[n, 1] = f1 * inv
        a[n, 2] = f2 * inv
