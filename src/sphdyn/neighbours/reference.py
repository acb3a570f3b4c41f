"""Brute-force O(N^2) reference of the neighbour search (for tests)."""

from __future__ import annotations

import numpy as np

from .build import _check_inputs


def brute_force_neighbours(x, h, radius_factor, skin, dim, active=None):
    """O(N^2) NumPy reference of ``build_neighbours`` (for tests).

    Evaluates the same floating-point pair test (see module docstring) for
    all pairs, in row blocks to bound memory.

    Returns
    -------
    offsets : (N + 1,) int64
    idx : (nnz,) int32
        Rows sorted ascending.
    """
    x, h, act = _check_inputs(x, h, radius_factor, skin, dim, active)
    n = x.shape[0]
    if act is None:
        act = np.ones(n, dtype=bool)
    half_rf = float(radius_factor) * 0.5
    skin = float(skin)
    rows, cols = [], []
    block = max(1, 2_000_000 // max(n, 1))
    for i0 in range(0, n, block):
        i1 = min(n, i0 + block)
        d0 = x[i0:i1, None, 0] - x[None, :, 0]
        d1 = x[i0:i1, None, 1] - x[None, :, 1]
        d2 = d0 * d0 + d1 * d1
        if dim == 3:
            dz = x[i0:i1, None, 2] - x[None, :, 2]
            d2 = d2 + dz * dz
        r = half_rf * (h[i0:i1, None] + h[None, :]) + skin
        m = d2 < r * r
        m &= act[i0:i1, None] & act[None, :]
        m[np.arange(i1 - i0), np.arange(i0, i1)] = False
        ri, ci = np.nonzero(m)
        rows.append(ri + i0)
        cols.append(ci)
    ri = np.concatenate(rows) if rows else np.empty(0, dtype=np.int64)
    ci = np.concatenate(cols) if cols else np.empty(0, dtype=np.int64)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(ri, minlength=n), out=offsets[1:])
    return offsets, ci.astype(np.int32)
