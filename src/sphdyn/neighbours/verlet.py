"""The Verlet list: ``NeighbourList``, its build, skin checks and rebuilds.

``build_neighbours`` builds a :class:`NeighbourList` (CSR arrays plus the
positions, smoothing lengths and active mask it was built from);
``needs_rebuild`` tells from the largest displacement (relative to the
common one) and growth of ``h`` since the build whether the skin still
covers every pair;
``update_neighbours`` rebuilds in place when it does not or when the
particle set changed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .build import _build_csr, _check_inputs, _idx_storage


class NeighbourList:
    """CSR Verlet list with the state it was built from.

    Attributes
    ----------
    offsets : (N + 1,) int64
        Row pointers; row ``i`` is ``idx[offsets[i]:offsets[i + 1]]``.
    idx : (nnz,) int32
        Neighbour indices, each row sorted ascending, symmetric, no self.
    x_ref : (N, 3) float64
        Copy of the positions at the last build [m].
    h_ref : (N,) float64
        Copy of the smoothing lengths at the last build [m].
    skin : float
        Verlet skin [m].
    radius_factor : float
        ``q_max * support_scale`` [-].
    dim : int
        2 or 3 (dimension used at the build).
    active_ref : (N,) bool or None
        Copy of the active mask used at the build (None = all active).
    n_builds : int
        Number of builds of this list (1 after ``build_neighbours``,
        incremented by every rebuild in ``update_neighbours``).
    cell_size : float
        Grid cell size of the last build [m] (diagnostic).
    n_big : int
        Number of large-h particles in the coarse grid of the last build
        (0: one grid; diagnostic).
    """

    def __init__(self, offsets, idx, x_ref, h_ref, skin, radius_factor, dim,
                 active_ref=None, n_builds=1, cell_size=0.0, n_big=0):
        self.offsets = offsets
        self.idx = idx
        self.x_ref = x_ref
        self.h_ref = h_ref
        self.skin = float(skin)
        self.radius_factor = float(radius_factor)
        self.dim = int(dim)
        self.active_ref = active_ref
        self.n_builds = int(n_builds)
        self.cell_size = float(cell_size)
        self.n_big = int(n_big)

    @property
    def n(self) -> int:
        """Number of particles (rows)."""
        return self.offsets.shape[0] - 1

    @property
    def nnz(self) -> int:
        """Total number of (directed) entries, i.e. twice the pair count."""
        return int(self.offsets[-1])

    def row(self, i: int) -> np.ndarray:
        """Neighbours of particle ``i`` (a view into ``idx``)."""
        return self.idx[self.offsets[i]:self.offsets[i + 1]]

    def __repr__(self) -> str:
        return (f"NeighbourList(n={self.n}, nnz={self.nnz}, dim={self.dim}, "
                f"skin={self.skin:g}, radius_factor={self.radius_factor:g}, "
                f"n_builds={self.n_builds})")


@njit(cache=True, error_model="numpy", parallel=True)
def _displacement_box(x, x_ref, h, h_ref, active, use_active, dim):
    """Bounding box of the displacements ``x_i - x_ref_i`` and the largest
    increase of h, over active particles.

    Returns ``(lo0, lo1, lo2, hi0, hi1, hi2, max(0, max_i (h_i - h_ref_i)))``
    (z components 0 in 2D); non-finite displacements are left out of the
    box (:func:`_max_disp_from` turns them into +inf), a NaN ``h`` gives
    +inf. ``min`` and ``max`` are exact and associative: the result does
    not depend on the thread count or the reduction order.
    """
    n = x.shape[0]
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    mdh = 0.0
    for i in prange(n):
        d0 = d1 = d2 = 0.0
        dh = 0.0
        take = (not use_active) or active[i]
        if take:
            d0 = x[i, 0] - x_ref[i, 0]
            d1 = x[i, 1] - x_ref[i, 1]
            if dim == 3:
                d2 = x[i, 2] - x_ref[i, 2]
            take = np.isfinite(d0) and np.isfinite(d1) and np.isfinite(d2)
            dh = h[i] - h_ref[i]
            if dh != dh:
                dh = np.inf
        mdh = max(mdh, dh)
        lo0 = min(lo0, d0 if take else np.inf)
        lo1 = min(lo1, d1 if take else np.inf)
        lo2 = min(lo2, d2 if take else np.inf)
        hi0 = max(hi0, d0 if take else -np.inf)
        hi1 = max(hi1, d1 if take else -np.inf)
        hi2 = max(hi2, d2 if take else -np.inf)
    return lo0, lo1, lo2, hi0, hi1, hi2, mdh


@njit(cache=True, error_model="numpy", parallel=True)
def _max_disp_from(x, x_ref, c0, c1, c2, active, use_active, dim):
    """``max_i |x_i - x_ref_i - c|^2`` and ``max_i |x_i - x_ref_i|^2`` over
    active particles (z ignored in 2D); NaN contributions become +inf.
    Deterministic (max reductions)."""
    n = x.shape[0]
    most_c = 0.0  # max |e - c|^2
    most_0 = 0.0  # max |e|^2
    for i in prange(n):
        sq_c = 0.0
        sq_0 = 0.0
        if (not use_active) or active[i]:
            e0 = x[i, 0] - x_ref[i, 0]
            e1 = x[i, 1] - x_ref[i, 1]
            e2 = x[i, 2] - x_ref[i, 2] if dim == 3 else 0.0
            sq_0 = e0 * e0 + e1 * e1 + e2 * e2
            sq_c = (e0 - c0) * (e0 - c0) + (e1 - c1) * (e1 - c1) + (e2 - c2) * (e2 - c2)
            if sq_0 != sq_0 or sq_c != sq_c:
                sq_0 = sq_c = np.inf
        most_c = max(most_c, sq_c)
        most_0 = max(most_0, sq_0)
    return most_c, most_0


@njit(cache=True, error_model="numpy")
def _mask_changed(active, active_ref):
    """True if ``active != 0`` differs from the bool mask ``active_ref``."""
    for i in range(active.shape[0]):
        if (active[i] != 0) != active_ref[i]:
            return True
    return False


_NO_MASK = np.empty(0, dtype=np.bool_)


def build_neighbours(x, h, radius_factor, skin, dim, active=None):
    """Build the Verlet list of all pairs within the h-dependent radius.

    Parameters
    ----------
    x : (N, 3) float64
        Positions [m] (z ignored when ``dim == 2``).
    h : (N,) float64
        Smoothing lengths [m], finite and >= 0 for active particles.
    radius_factor : float
        ``q_max * support_scale`` [-]; the pair radius is
        ``radius_factor * 0.5 * (h_i + h_j) + skin``.
    skin : float
        Verlet skin [m], >= 0.
    dim : int
        2 or 3.
    active : (N,) bool or int array, optional
        Nonzero = active. Inactive particles get empty rows and appear in no
        row. Default: all active.

    Returns
    -------
    NeighbourList
        CSR list (rows sorted ascending, symmetric, no self entries) with
        copies of ``x``, ``h`` and ``active`` and ``n_builds == 1``.

    Notes
    -----
    Cell-linked list + two-pass CSR fill, see the module docstring. Ties at
    exactly the radius are excluded (strict ``<`` on squared distances).
    """
    x, h, act = _check_inputs(x, h, radius_factor, skin, dim, active)
    offsets, idx, idx_buf, cs, n_big = _build_csr(
        x, h, act, float(radius_factor), float(skin), dim)
    return NeighbourList(offsets, idx, x.copy(), h.copy(), skin,
                         radius_factor, dim,
                         None if act is None else act.copy(), 1, cs, n_big)


def max_displacement(nl, x, h):
    """Largest displacement since the last build, relative to the common
    one, and the largest increase of h.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64, h : (N,) float64
        Current positions [m] and smoothing lengths [m].

    Returns
    -------
    (float, float)
        ``max_i |x_i - x_ref_i - c|`` [m] (x, y only in 2D), with ``c`` the
        centre of the bounding box of the displacements ``x_i - x_ref_i``
        (a body moving as a whole gives 0) or ``c = 0`` if that gives less
        (the box's centre is not the smallest enclosing ball's), and
        ``max(0, max_i (h_i - h_ref_i))`` [m], over the particles active at
        the build. NaN gives +inf. Deterministic (min and max reductions).
    """
    use_active = nl.active_ref is not None
    act = nl.active_ref if use_active else _NO_MASK
    lo0, lo1, lo2, hi0, hi1, hi2, dh = _displacement_box(x, nl.x_ref, h, nl.h_ref, act,
                                                         use_active, nl.dim)
    if lo0 > hi0:  # no finite displacement (no active particle, or all NaN)
        c0 = c1 = c2 = 0.0
    else:
        c0, c1, c2 = 0.5 * (lo0 + hi0), 0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2)
    dc2, d02 = _max_disp_from(x, nl.x_ref, c0, c1, c2, act, use_active, nl.dim)
    return math.sqrt(min(dc2, d02)), dh


def needs_rebuild(nl, x, h):
    """True when the list may miss a pair that is now within its radius.

    The test is ``2 * max_i |x_i - x_ref_i - c| + radius_factor *
    max(0, max_i (h_i - h_ref_i)) > skin`` over the particles active at the
    build, for a common displacement ``c`` (:func:`max_displacement`: the
    centre of the displacements' bounding box, or 0).

    Why it suffices: a pair's separation does not change when both move by
    the same ``c``, so only the displacements relative to it count. Let
    ``d = max |x_i - x_ref_i - c|`` and ``e = max(0, max (h_i - h_ref_i))``.
    Since ``(x_i - x_j) - (x_ref_i - x_ref_j) = (x_i - x_ref_i - c) -
    (x_j - x_ref_j - c)``, the triangle inequality gives ``|x_ref_i -
    x_ref_j| <= |x_i - x_j| + 2 d``. If a pair is within its *current*
    radius without skin, ``|x_i - x_j| < rf * 0.5 * (h_i + h_j)``, and,
    since each ``h`` grew by at most ``e``, ``rf * 0.5 * (h_i + h_j) <= rf *
    0.5 * (h_ref_i + h_ref_j) + rf * e``. Hence ``|x_ref_i - x_ref_j| < rf *
    0.5 * (h_ref_i + h_ref_j) + 2 d + rf * e <= ... + skin`` whenever ``2 d
    + rf e <= skin``: the pair satisfied the build criterion and is in the
    list. (Shrinking ``h`` only shrinks the current radius, so only the
    increase counts.) A body flying as a whole (a projectile, the paper's
    disc before its impact) thus needs no rebuild, however far it flies.
    The argument is exact in real arithmetic; floating-point
    evaluation of the distances can only matter for pairs within a few ulps
    of the radius. The list may contain extra pairs beyond the current
    radius; kernels must still test the distance. Changes of the active set
    are not seen here; ``update_neighbours`` handles them. Inactive
    particles (at the build) are ignored in the maxima, so eroded particles
    flying away do not trigger rebuilds.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64
        Current positions [m].
    h : (N,) float64
        Current smoothing lengths [m].

    Returns
    -------
    bool
    """
    if x.shape[0] != nl.n or h.shape[0] != nl.n:
        return True
    d, dh = max_displacement(nl, x, h)
    return 2.0 * d + nl.radius_factor * dh > nl.skin


def update_neighbours(nl, x, h, dim, active=None):
    """Rebuild ``nl`` in place if needed; return it.

    A rebuild happens when ``needs_rebuild(nl, x, h)``, or when the number of
    particles, ``dim`` or the active mask differ from those of the last build
    (an activated particle would otherwise be missing, a deactivated one
    would remain). On rebuild ``offsets``, ``x_ref``, ``h_ref`` and the
    storage of ``idx`` are overwritten in place when their size allows (no
    allocation of the large arrays, lower peak memory; ``idx`` becomes a
    view of a buffer with up to 10 % spare capacity when it has to grow),
    and ``n_builds`` is incremented. Arrays obtained from ``nl`` before the
    call must not be kept across it.

    Parameters
    ----------
    nl : NeighbourList
    x : (N, 3) float64, h : (N,) float64
        Current positions [m] and smoothing lengths [m].
    dim : int
        2 or 3.
    active : (N,) bool or int array, optional
        Current active mask (None = all active).

    Returns
    -------
    NeighbourList
        ``nl`` itself (rebuilt or not).
    """
    n = nl.n
    rebuild = (x.shape[0] != n or h.shape[0] != n or dim != nl.dim
               or (active is None) != (nl.active_ref is None))
    if not rebuild and active is not None:
        a = np.asarray(active)
        rebuild = a.shape != (n,) or _mask_changed(a, nl.active_ref)
    if not rebuild:
        rebuild = needs_rebuild(nl, x, h)
    if not rebuild:
        return nl
    x, h, act = _check_inputs(x, h, nl.radius_factor, nl.skin, dim, active)
    offsets, idx, _, cs, n_big = _build_csr(
        x, h, act, nl.radius_factor, nl.skin, dim, nl.offsets,
        _idx_storage(nl.idx))
    nl.offsets = offsets
    nl.idx = idx
    if nl.x_ref.shape == x.shape:
        nl.x_ref[...] = x
        nl.h_ref[...] = h
    else:
        nl.x_ref = x.copy()
        nl.h_ref = h.copy()
    if act is None:
        nl.active_ref = None
    elif nl.active_ref is not None and nl.active_ref.shape == act.shape:
        nl.active_ref[...] = act
    else:
        nl.active_ref = act.copy()
    nl.dim = int(dim)
    nl.cell_size = cs
    nl.n_big = n_big
    nl.n_builds += 1
    return nl
