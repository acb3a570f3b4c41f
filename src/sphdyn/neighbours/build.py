"""CSR build: input checks, counting and filling the rows, sorted storage.

``_build_csr`` runs the two passes of step 5 of the algorithm (see
:mod:`sphdyn.neighbours`) on validated inputs: ``_count_rows`` gives the row
lengths and, after a prefix sum, the row offsets; ``_fill_rows`` writes every
row sorted ascending (``_sorted_store``: rank sort for short rows, heap sort
for long ones) into the ``idx`` buffer, which rebuilds reuse.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .grid import _bounds, _choose_h_cut, _make_grid
from .rows import _collect_cells, _count_cells

# Rows up to this length are sorted by rank sort, longer ones by heap sort.
_RANK_SORT_MAX = 128
# Spare capacity of a reallocated idx buffer (rebuilds reuse the storage).
_IDX_HEADROOM = 0.1
# Particles per prange chunk of the fill pass (one scratch buffer per chunk).
_FILL_CHUNK = 1024


@njit(cache=True, error_model="numpy")
def _sift_down(a, lo, root, end):
    """Restore the max-heap property of ``a[lo:lo + end]`` below ``root``."""
    v = a[lo + root]
    while True:
        child = 2 * root + 1
        if child >= end:
            break
        if child + 1 < end and a[lo + child] < a[lo + child + 1]:
            child += 1
        if v >= a[lo + child]:
            break
        a[lo + root] = a[lo + child]
        root = child
    a[lo + root] = v


@njit(cache=True, error_model="numpy")
def _heap_sort(a, lo, hi):
    """Sort ``a[lo:hi]`` ascending in place (heap sort: O(n log n), no
    recursion, no allocation)."""
    n = hi - lo
    for root in range(n // 2 - 1, -1, -1):
        _sift_down(a, lo, root, n)
    for end in range(n - 1, 0, -1):
        t = a[lo]
        a[lo] = a[lo + end]
        a[lo + end] = t
        _sift_down(a, lo, 0, end)


@njit(cache=True, error_model="numpy")
def _sorted_store(buf, n, out, pos):
    """Store the ``n`` distinct values of ``buf`` sorted into ``out[pos:]``.

    Short rows (``n <= 128``): rank sort, ``out[pos + #{m: buf[m] < v}] = v``
    (branch-free, vectorised, O(n^2)); longer rows: copy and heap sort.
    """
    if n <= _RANK_SORT_MAX:
        for k in range(n):
            v = buf[k]
            r = np.int32(0)
            for m in range(n):
                r += np.int32(buf[m] < v)
            out[pos + r] = v
    else:
        for k in range(n):
            out[pos + k] = buf[k]
        _heap_sort(out, pos, pos + n)


@njit(cache=True, error_model="numpy", parallel=True)
def _count_rows(visit, counts, x, h, dim, half_rf, skin, fine, coarse):
    """Pass 1: ``counts[i + 1]`` = number of neighbours of ``i``.

    ``visit`` lists the fine grid's particles in cell order followed by the
    coarse grid's (``fine``, ``coarse``: :func:`.grid._make_grid`).
    """
    has_coarse = coarse[5][-1] > 0
    for t in prange(visit.shape[0]):
        i = visit[t]
        n = _count_cells(i, x, h, dim, half_rf, skin, *fine)
        if has_coarse:
            n += _count_cells(i, x, h, dim, half_rf, skin, *coarse)
        # i itself was counted (it is in one of the grids): the same test
        r = half_rf * (h[i] + h[i]) + skin
        counts[i + 1] = n - (0.0 < r * r)


@njit(cache=True, error_model="numpy", parallel=True)
def _fill_rows(visit, offsets, idx, max_row, x, h, dim, half_rf, skin, fine,
               coarse):
    """Pass 2: write every row of ``idx`` sorted ascending.

    ``visit`` is processed in ``_FILL_CHUNK``-sized chunks, each with its own
    scratch buffer of ``max_row + 1`` entries. Returns the number of rows
    whose length differs from pass 1 (must be 0; such rows are truncated,
    never written out of bounds).
    """
    nv = visit.shape[0]
    nchunk = (nv + _FILL_CHUNK - 1) // _FILL_CHUNK
    bad = 0
    has_coarse = coarse[5][-1] > 0
    for c in prange(nchunk):
        buf = np.empty(max_row + 1, dtype=np.int32)
        for t in range(c * _FILL_CHUNK, min(nv, (c + 1) * _FILL_CHUNK)):
            i = visit[t]
            n = _collect_cells(i, 0, buf, x, h, dim, half_rf, skin, *fine)
            if has_coarse:
                n = _collect_cells(i, n, buf, x, h, dim, half_rf, skin,
                                   *coarse)
            cnt = offsets[i + 1] - offsets[i]
            if n != cnt:
                bad += 1
                n = min(n, cnt)
            _sorted_store(buf, n, idx, offsets[i])
    return bad


def _check_inputs(x, h, radius_factor, skin, dim, active):
    """Validated ``(x, h, act)``: contiguous float64 ``x``, ``h`` and a bool
    ``act`` (None = all active); ValueError naming the bad argument."""
    if dim not in (1, 2, 3):  # 1: along x, y = z = 0
        raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
    x = np.ascontiguousarray(x, dtype=np.float64)
    h = np.ascontiguousarray(h, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must have shape (N, 3), got {x.shape}")
    n = x.shape[0]
    if h.shape != (n,):
        raise ValueError(f"h must have shape ({n},), got {h.shape}")
    if n >= 2**31 - 1:
        raise ValueError("too many particles for int32 neighbour indices")
    if not (np.isfinite(radius_factor) and radius_factor > 0.0):
        raise ValueError(f"radius_factor must be > 0, got {radius_factor}")
    if not (np.isfinite(skin) and skin >= 0.0):
        raise ValueError(f"skin must be >= 0, got {skin}")
    if active is None:
        act = None
    else:
        act = np.asarray(active)
        if act.shape != (n,):
            raise ValueError(f"active must have shape ({n},), got {act.shape}")
        act = np.ascontiguousarray(act != 0)
    return x, h, act


def _idx_storage(idx):
    """Writable int32 buffer whose leading part is ``idx`` (its base array if
    ``idx`` is a leading view of one, else ``idx`` itself), or None."""
    if not (isinstance(idx, np.ndarray) and idx.dtype == np.int32
            and idx.ndim == 1 and idx.flags.c_contiguous
            and idx.flags.writeable):
        return None
    b = idx.base
    if (isinstance(b, np.ndarray) and b.dtype == np.int32 and b.ndim == 1
            and b.flags.c_contiguous and b.flags.writeable
            and b.ctypes.data == idx.ctypes.data):
        return b
    return idx


def _build_csr(x, h, act, rf, skin, dim, offsets_buf=None, idx_buf=None):
    """Return ``(offsets, idx, idx_buf, cell_size, n_big)`` for validated
    inputs.

    ``offsets_buf`` ((N + 1,) int64) and ``idx_buf`` (int32) are reused if
    given and large enough; ``idx`` is a leading view of ``idx_buf``.
    A new ``idx_buf`` gets ``_IDX_HEADROOM`` spare capacity (the first build
    too: a rebuild that finds a few more pairs then writes into the same
    buffer instead of holding an old and a new list at once).
    """
    n = x.shape[0]
    act_ids = (np.arange(n, dtype=np.int64) if act is None
               else np.flatnonzero(act).astype(np.int64))
    n_act = act_ids.shape[0]
    if n_act > 0:  # validate before touching the buffers of the old list
        xa = x[act_ids]
        ha = h[act_ids]
        if not np.all(np.isfinite(xa[:, :dim])):
            raise ValueError("non-finite position of an active particle")
        if not np.all(np.isfinite(ha)) or ha.min() < 0.0:
            raise ValueError("h of active particles must be finite and >= 0")
    if (isinstance(offsets_buf, np.ndarray) and offsets_buf.shape == (n + 1,)
            and offsets_buf.dtype == np.int64 and offsets_buf.flags.writeable
            and offsets_buf.flags.c_contiguous):
        offsets = offsets_buf
        offsets[:] = 0
    else:
        offsets = np.zeros(n + 1, dtype=np.int64)
    if n_act == 0:
        if idx_buf is None:
            idx_buf = np.empty(0, dtype=np.int32)
        return offsets, idx_buf[:0], idx_buf, 0.0, 0
    h_cut, big_mask = _choose_h_cut(ha, xa, rf, skin, dim)
    half_rf = rf * 0.5
    if big_mask is None:
        big = np.empty(0, dtype=np.int64)
        fine, cs = _make_grid(x, h, act_ids, h_cut, half_rf, skin, dim,
                              _bounds(xa, dim))
    else:
        big = act_ids[big_mask]
        fine, cs = _make_grid(x, h, act_ids[~big_mask], h_cut, half_rf,
                              skin, dim)
    coarse, _ = _make_grid(x, h, big, float(h[big].max()) if big.shape[0]
                           else 0.0, half_rf, skin, dim)
    visit = np.concatenate((fine[6].astype(np.int64),
                            coarse[6].astype(np.int64)))
    args = (x, h, dim, half_rf, skin, fine, coarse)
    _count_rows(visit, offsets, *args)
    max_row = int(offsets.max())
    np.cumsum(offsets, out=offsets)
    nnz = int(offsets[-1])
    if idx_buf is None or idx_buf.shape[0] < nnz:
        # spare capacity for the rebuilds (its pages are not resident until
        # a longer list writes them, so it costs no memory before)
        idx_buf = np.empty(int(nnz * (1.0 + _IDX_HEADROOM)), dtype=np.int32)
    idx = idx_buf[:nnz]
    bad = _fill_rows(visit, offsets, idx, max_row, *args)
    if bad:
        raise RuntimeError(f"neighbour search: {bad} rows changed length "
                           "between count and fill passes")
    return offsets, idx, idx_buf, cs, big.shape[0]
