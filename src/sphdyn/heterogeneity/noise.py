"""Coherent noise evaluated at arbitrary points: gradient noise, fBm, cellular.

All functions take points as a ``(N, 3)`` float64 array in metres (z = 0 for
2D bodies) and return ``(N,)`` arrays; they are deterministic functions of the
points and the integer ``seed`` (bitwise identical for any thread count, since
every point is evaluated independently).

Gradient noise (Perlin 1985; "improved noise", Perlin 2002)
-----------------------------------------------------------
For a point ``p`` with integer lattice cell ``i = floor(p)`` and local
coordinates ``f = p - i`` in [0, 1)^3,

.. math::

    n(p) = \\sum_{c \\in \\{0,1\\}^3} w(f - c)\\; g_{h(i+c)} \\cdot (f - c),
    \\qquad w(d) = \\prod_{a} s(1 - |d_a|),\\quad
    s(t) = 6t^5 - 15t^4 + 10t^3,

where ``g_h`` is one of the 12 cube-edge vectors (1,1,0), (1,0,1), ... chosen
by a seeded permutation hash ``h`` of the corner (Perlin 2002, with the
quintic fade ``s`` that makes ``n`` C2-continuous). Properties used by the
tests: ``n = 0`` at every lattice point (each corner term vanishes there), and
``|n| <= sqrt(2) * sqrt(3)`` because the weights sum to one (partition of
unity) and ``|g| = sqrt(2)``, ``|f - c| <= sqrt(3)``; in practice
``|n| < 1.04``.

Fractional Brownian motion (Mandelbrot & Van Ness 1968; Musgrave in Ebert et
al., "Texturing and Modeling", 2003)
-------------------------------------------------------------------------
.. math::

    F(x) = \\sum_{k=0}^{K-1} p^k\\, n_k\\!\\left(\\lambda^k x / L + o_k\\right)

with ``K`` octaves, persistence ``p`` (amplitude ratio), lacunarity
``lambda`` (frequency ratio), feature size ``L`` (m) and per-octave random
offsets ``o_k``. Every octave uses its own permutation table, so the octaves
are independent random fields and ``Var F = sigma_n^2 sum_k p^{2k}``
(``sigma_n^2`` the variance of one octave), which the tests check. The
*ridged* variant (Musgrave's ridged multifractal without the spectral
feedback) sums ``p^k (1 - |n_k|)^2``: sharp crests where ``n_k`` changes sign.

Cellular noise (Worley 1996)
----------------------------
Seeds on a jittered lattice of spacing ``c`` (one seed per cell at
``c (m + 1/2 + j (u - 1/2))``, ``u`` uniform in [0, 1)^3 from a hash of the
cell index ``m`` and the seed, jitter ``j`` in [0, 1]) define Voronoi cells.
For each point, ``F1`` is the distance to the nearest seed ``a`` and the
distance to the boundary of its Voronoi cell is

.. math::

    d_{face}(x) = \\min_{b \\ne a}
                  \\frac{|x - s_b|^2 - |x - s_a|^2}{2\\,|s_b - s_a|}

(distance to the nearest bisector plane, exact for the convex cell). Seeds
are searched in the 7 x 7 x 7 block of cells around the point (7 x 7 x 1 in
2D, where the seeds lie in the plane z = 0 and the cells are polygons),
skipping cells whose seed box cannot beat the current best (lower bounds
``|x - s_b| >= box distance`` and ``d_b >= (|x - s_b| - F1) / 2``). With
``j <= 0.9`` the nearest seed lies within +-2 cells and a seed 4 cells away
has a bisector at >= 0.7 c, beyond the largest in-cell distance seen
(the tests compare with a brute-force search over all seeds).

Why Numba and not a noise library: the maintained Python noise packages are
either C extensions without releases for current Pythons (``noise``) or
evaluate one point per Python call (``perlin-noise``, ``opensimplex``'s
scalar API; its array API covers only grids). Evaluating a million particle
positions directly, in parallel, with per-octave independent tables and the
cellular variant in the same code path takes a few hundred lines of Numba.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

__all__ = ["permutation_tables", "gradient_noise", "fbm", "Cellular",
           "cellular", "grid_points"]

_TABLE = 256
_SOFT_CUT = 5.0


def permutation_tables(seed: int, count: int) -> np.ndarray:
    """``count`` independent permutation tables of 0..255, doubled to 512.

    Returns int64 ``(count, 512)``; row ``k`` drives octave ``k``. Drawn from
    ``numpy.random.default_rng(seed)`` so a seed fixes the whole field.
    """
    rng = np.random.default_rng(seed)
    out = np.empty((count, 2 * _TABLE), dtype=np.int64)
    for k in range(count):
        p = rng.permutation(_TABLE)
        out[k, :_TABLE] = p
        out[k, _TABLE:] = p
    return out


@njit(cache=True, error_model="numpy", inline="always")
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@njit(cache=True, error_model="numpy", inline="always")
def _grad(h, x, y, z):
    # dot product with one of the 12 cube-edge vectors (Perlin 2002)
    h = h & 15
    u = x if h < 8 else y
    if h < 4:
        v = y
    elif h == 12 or h == 14:
        v = x
    else:
        v = z
    return (u if (h & 1) == 0 else -u) + (v if (h & 2) == 0 else -v)


@njit(cache=True, error_model="numpy")
def _perlin(x, y, z, p):
    fx = np.floor(x)
    fy = np.floor(y)
    fz = np.floor(z)
    X = int(fx) & 255
    Y = int(fy) & 255
    Z = int(fz) & 255
    x -= fx
    y -= fy
    z -= fz
    u = _fade(x)
    v = _fade(y)
    w = _fade(z)
    A = p[X] + Y
    AA = p[A] + Z
    AB = p[A + 1] + Z
    B = p[X + 1] + Y
    BA = p[B] + Z
    BB = p[B + 1] + Z
    x1 = x - 1.0
    y1 = y - 1.0
    z1 = z - 1.0
    l1 = (_grad(p[AA], x, y, z)
          + u * (_grad(p[BA], x1, y, z) - _grad(p[AA], x, y, z)))
    l2 = (_grad(p[AB], x, y1, z)
          + u * (_grad(p[BB], x1, y1, z) - _grad(p[AB], x, y1, z)))
    l3 = (_grad(p[AA + 1], x, y, z1)
          + u * (_grad(p[BA + 1], x1, y, z1) - _grad(p[AA + 1], x, y, z1)))
    l4 = (_grad(p[AB + 1], x, y1, z1)
          + u * (_grad(p[BB + 1], x1, y1, z1) - _grad(p[AB + 1], x, y1, z1)))
    m1 = l1 + v * (l2 - l1)
    m2 = l3 + v * (l4 - l3)
    return m1 + w * (m2 - m1)


@njit(cache=True, error_model="numpy", parallel=True)
def _fbm_kernel(pts, scale, tables, offsets, persistence, lacunarity, ridged,
                out):
    n = pts.shape[0]
    K = tables.shape[0]
    for i in prange(n):
        freq = scale
        amp = 1.0
        acc = 0.0
        for k in range(K):
            v = _perlin(pts[i, 0] * freq + offsets[k, 0],
                        pts[i, 1] * freq + offsets[k, 1],
                        pts[i, 2] * freq + offsets[k, 2], tables[k])
            if ridged:
                r = 1.0 - abs(v)
                v = r * r
            acc += amp * v
            amp *= persistence
            freq *= lacunarity
        out[i] = acc


def _as_points(points) -> np.ndarray:
    pts = np.ascontiguousarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3) (z = 0 in 2D), got "
                         f"{pts.shape}")
    return pts


def gradient_noise(points, seed: int = 0) -> np.ndarray:
    """Improved Perlin gradient noise (Perlin 2002) at ``points``.

    ``points``: (N, 3) in lattice units (one lattice cell = 1). Returns (N,)
    float64; zero at integer points, ``|n| <= sqrt(6)`` (see module doc).
    """
    pts = _as_points(points)
    out = np.empty(pts.shape[0])
    _fbm_kernel(pts, 1.0, permutation_tables(seed, 1), np.zeros((1, 3)),
                1.0, 1.0, False, out)
    return out


def fbm(points, *, feature_size: float, octaves: int = 4,
        persistence: float = 0.5, lacunarity: float = 2.0, seed: int = 0,
        ridged: bool = False) -> np.ndarray:
    """Fractional Brownian motion of gradient noise (module doc, eq. F).

    ``points`` (N, 3) in m; ``feature_size`` L in m (the lattice spacing of
    the first octave); returns (N,) float64, not normalised (variance
    ``sigma_n^2 sum p^{2k}``; ridged: values in [0, sum p^k]).
    """
    pts = _as_points(points)
    if not feature_size > 0:
        raise ValueError(f"feature_size must be > 0 m, got {feature_size}")
    if octaves < 1:
        raise ValueError(f"octaves must be >= 1, got {octaves}")
    if not lacunarity > 0 or not persistence > 0:
        raise ValueError("persistence and lacunarity must be > 0, got "
                         f"{persistence}, {lacunarity}")
    tables = permutation_tables(seed, octaves)
    # offsets in [0, 256): decorrelate octaves and move the origin (and the
    # plane z = 0 of 2D bodies) off the lattice planes
    offsets = np.random.default_rng([seed, 1]).random((octaves, 3)) * _TABLE
    out = np.empty(pts.shape[0])
    _fbm_kernel(pts, 1.0 / feature_size, tables, offsets, float(persistence),
                float(lacunarity), bool(ridged), out)
    return out


@njit(cache=True, error_model="numpy", inline="always")
def _mix64(z):
    # splitmix64 finaliser (Steele, Lea & Flood 2014), uint64 arithmetic
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True, error_model="numpy", inline="always")
def _seed_pos(i, j, k, key, jitter, dim):
    # seed of cell (i, j, k) in cell units; indices are shifted positive
    h = (np.uint64(i + 1048576) * np.uint64(0x9E3779B97F4A7C15)
         ^ np.uint64(j + 1048576) * np.uint64(0xC2B2AE3D27D4EB4F)
         ^ np.uint64(k + 1048576) * np.uint64(0x165667B19E3779F9) ^ key)
    h1 = _mix64(h)
    h2 = _mix64(h1 + np.uint64(0x9E3779B97F4A7C15))
    h3 = _mix64(h2 + np.uint64(0x9E3779B97F4A7C15))
    s53 = 1.0 / 9007199254740992.0
    ux = float(h1 >> np.uint64(11)) * s53
    uy = float(h2 >> np.uint64(11)) * s53
    uz = float(h3 >> np.uint64(11)) * s53
    sx = i + 0.5 + jitter * (ux - 0.5)
    sy = j + 0.5 + jitter * (uy - 0.5)
    sz = k + 0.5 + jitter * (uz - 0.5) if dim == 3 else 0.0
    return sx, sy, sz


@njit(cache=True, error_model="numpy", parallel=True)
def _seed_table(lo, shape, key, jitter, dim, out):
    # seed positions (cell units) of the cells lo + (0..shape-1)
    for a in prange(shape[0]):
        for b in range(shape[1]):
            for c in range(shape[2]):
                sx, sy, sz = _seed_pos(lo[0] + a, lo[1] + b, lo[2] + c, key,
                                       jitter, dim)
                out[a, b, c, 0] = sx
                out[a, b, c, 1] = sy
                out[a, b, c, 2] = sz


@njit(cache=True, error_model="numpy", inline="always")
def _box_d1(p, i, half):
    # distance along one axis from p to the interval that can hold the seed
    # of cell i (cell units)
    return max(i + 0.5 - half - p, 0.0, p - (i + 0.5 + half))


@njit(cache=True, error_model="numpy", inline="always")
def _nearest(px, py, pz, cx, cy, cz, r, rz, half, seeds, lo, best, bi, bj,
             bk):
    # nearest seed among cells within +-r (+-rz in z) of cell c, starting
    # from the candidate (best, bi, bj, bk); slabs and rows that cannot beat
    # `best` are skipped
    for i in range(cx - r, cx + r + 1):
        ex = _box_d1(px, i, half) ** 2
        if ex >= best:
            continue
        for j in range(cy - r, cy + r + 1):
            ey = ex + _box_d1(py, j, half) ** 2
            if ey >= best:
                continue
            for k in range(cz - rz, cz + rz + 1):
                if ey + _box_d1(pz, k, half) ** 2 >= best:
                    continue
                s = seeds[i - lo[0], j - lo[1], k - lo[2]]
                d2 = (px - s[0]) ** 2 + (py - s[1]) ** 2 + (pz - s[2]) ** 2
                if d2 < best:
                    best = d2
                    bi = i
                    bj = j
                    bk = k
    return best, bi, bj, bk


@njit(cache=True, error_model="numpy", inline="always")
def _bisector(px, py, pz, cx, cy, cz, r, rz, half, seeds, lo, best, bi, bj,
              bk, bound, tau):
    # min over seeds b != a of the distance d_b to the bisector plane of a, b
    # and, for tau > 0, the soft minimum -tau log sum exp(-d_b / tau) over
    # the seeds with d_b <= min + 5 tau (each dropped term < e^-5 of the
    # largest; the soft minimum is a shape function, not a distance).
    # A seed b cannot give less than (|p - b| - |p - a|) / 2; `bound` (>=
    # the minimum, from a smaller block; the exact minimum for tau > 0)
    # tightens the pruning.
    r1 = np.sqrt(best)
    a = seeds[bi - lo[0], bj - lo[1], bk - lo[2]]
    m = np.inf
    ssum = 0.0
    # prune when (sqrt(e) - r1) / 2 > min(m, bound) + cut tau, i.e. e > lim2
    cut = min(m, bound) + _SOFT_CUT * tau
    lim2 = (2.0 * cut + r1) ** 2
    for i in range(cx - r, cx + r + 1):
        ex = _box_d1(px, i, half) ** 2
        if ex > lim2:
            continue
        for j in range(cy - r, cy + r + 1):
            ey = ex + _box_d1(py, j, half) ** 2
            if ey > lim2:
                continue
            for k in range(cz - rz, cz + rz + 1):
                if i == bi and j == bj and k == bk:
                    continue
                ez = ey + _box_d1(pz, k, half) ** 2
                if ez > lim2:
                    continue
                s = seeds[i - lo[0], j - lo[1], k - lo[2]]
                d2 = (px - s[0]) ** 2 + (py - s[1]) ** 2 + (pz - s[2]) ** 2
                sep = np.sqrt((s[0] - a[0]) ** 2 + (s[1] - a[1]) ** 2
                              + (s[2] - a[2]) ** 2)
                d = (d2 - best) / (2.0 * sep)
                if tau > 0.0:
                    if d > cut:
                        continue
                    if ssum == 0.0:
                        ssum = 1.0
                        m = d
                    elif d < m:
                        ssum = ssum * np.exp((d - m) / tau) + 1.0
                        m = d
                    else:
                        ssum += np.exp((m - d) / tau)
                elif d < m:
                    m = d
                    if m < cut:
                        cut = m
                        lim2 = (2.0 * cut + r1) ** 2
    if tau > 0.0:
        return m, m - tau * np.log(ssum)
    return m, m


@njit(cache=True, error_model="numpy", parallel=True)
def _cellular_kernel(pts, inv_c, origin, seeds, lo, jitter, dim, tau, f1,
                     dface, dsoft, cell):
    n = pts.shape[0]
    rz1 = 1 if dim == 3 else 0
    rz2 = 2 if dim == 3 else 0
    rz3 = 3 if dim == 3 else 0
    half = 0.5 * jitter
    for q in prange(n):
        px = pts[q, 0] * inv_c + origin[0]
        py = pts[q, 1] * inv_c + origin[1]
        pz = pts[q, 2] * inv_c + origin[2] if dim == 3 else 0.0
        cx = int(np.floor(px))
        cy = int(np.floor(py))
        cz = int(np.floor(pz)) if dim == 3 else 0
        s = seeds[cx - lo[0], cy - lo[1], cz - lo[2]]
        best = (px - s[0]) ** 2 + (py - s[1]) ** 2 + (pz - s[2]) ** 2
        # near block first (a good bound), then the full block with pruning
        best, bi, bj, bk = _nearest(px, py, pz, cx, cy, cz, 1, rz1, half,
                                    seeds, lo, best, cx, cy, cz)
        best, bi, bj, bk = _nearest(px, py, pz, cx, cy, cz, 3, rz3, half,
                                    seeds, lo, best, bi, bj, bk)
        # near block: an upper bound of the minimum for the pruning
        bound, ds = _bisector(px, py, pz, cx, cy, cz, 1, rz1, half, seeds,
                              lo, best, bi, bj, bk, np.inf, 0.0)
        dmin, ds = _bisector(px, py, pz, cx, cy, cz, 3, rz3, half, seeds,
                             lo, best, bi, bj, bk, bound, 0.0)
        if tau > 0.0:
            # soft minimum over the +-2 block only (cost); seeds farther
            # away have d_b >= 0.2 c + min in all but rare configurations
            bound, ds = _bisector(px, py, pz, cx, cy, cz, 2, rz2, half,
                                  seeds, lo, best, bi, bj, bk, dmin, tau)
        f1[q] = np.sqrt(best)
        dface[q] = dmin
        dsoft[q] = ds
        cell[q, 0] = bi - lo[0]
        cell[q, 1] = bj - lo[1]
        cell[q, 2] = bk - lo[2]


class Cellular(NamedTuple):
    """Result of :func:`cellular` (all (N,), lengths in m)."""

    f1: np.ndarray      #: distance to the nearest seed
    dface: np.ndarray   #: distance to the boundary of its Voronoi cell
    dsoft: np.ndarray   #: soft minimum of the bisector distances (<= dface)
    cell: np.ndarray    #: int64 id of the Voronoi cell (equal ids = same cell)


def cellular(points, *, cell_size: float, seed: int = 0, dim: int = 3,
             jitter: float = 0.9, softness: float = 0.0) -> Cellular:
    """Worley cellular noise on a jittered seed lattice (module doc).

    ``points`` (N, 3) in m, ``cell_size`` c in m; ``dim = 2`` uses seeds in
    the plane z = 0 (polygonal cells). ``softness`` tau (m, >= 0) also
    returns the soft minimum ``-tau log sum_b exp(-d_b / tau)`` of the
    bisector distances, whose level sets are the cell's polytope with
    edges and corners rounded over a length ~ tau (equal to ``dface`` for
    tau = 0).
    """
    pts = _as_points(points)
    if not cell_size > 0:
        raise ValueError(f"cell_size must be > 0 m, got {cell_size}")
    if not 0.0 <= jitter <= 0.9:
        raise ValueError(f"jitter must be in [0, 0.9], got {jitter}")
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    if not softness >= 0:
        raise ValueError(f"softness must be >= 0 m, got {softness}")
    rng = np.random.default_rng([seed, 2])
    origin = rng.random(3) * 64.0  # lattice origin off the coordinate planes
    key = np.uint64(int(rng.integers(0, 2**63 - 1)))
    n = pts.shape[0]
    f1 = np.empty(n)
    dface = np.empty(n)
    dsoft = np.empty(n)
    cell = np.empty((n, 3), dtype=np.int64)
    if n == 0:
        return Cellular(f1, dface, dsoft, np.empty(0, dtype=np.int64))
    u = pts / cell_size + origin
    lo = np.floor(u.min(axis=0)).astype(np.int64) - 3
    hi = np.floor(u.max(axis=0)).astype(np.int64) + 4
    if dim == 2:
        lo[2], hi[2] = 0, 1
    ext = hi - lo
    seeds = np.empty((ext[0], ext[1], ext[2], 3))
    _seed_table(lo, ext, key, float(jitter), dim, seeds)
    _cellular_kernel(pts, 1.0 / cell_size, origin, seeds, lo, float(jitter),
                     dim, softness / cell_size, f1, dface, dsoft, cell)
    cid = (cell[:, 0] * ext[1] + cell[:, 1]) * ext[2] + cell[:, 2]
    return Cellular(f1 * cell_size, dface * cell_size, dsoft * cell_size,
                    cid)


def grid_points(shape, dx: float, origin=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Voxel-centre coordinates of a regular grid, (prod(shape), 3) in m.

    ``shape`` is (nx, ny) or (nx, ny, nz); voxel (i, j, k) has centre
    ``origin + dx * (i, j, k)``; order is C order of ``shape`` (so
    ``values.reshape(shape)`` gives the grid). 2D grids get z = origin z.
    """
    shape = tuple(int(s) for s in shape)
    if len(shape) not in (2, 3) or min(shape) < 1:
        raise ValueError(f"grid shape must be (nx, ny) or (nx, ny, nz) with "
                         f"positive sizes, got {shape}")
    axes = [origin[a] + dx * np.arange(s) for a, s in enumerate(shape)]
    mesh = np.meshgrid(*axes, indexing="ij")
    pts = np.zeros((mesh[0].size, 3))
    for a, m in enumerate(mesh):
        pts[:, a] = m.ravel()
    if len(shape) == 2:
        pts[:, 2] = origin[2]
    return pts
