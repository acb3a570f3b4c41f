"""Regular particle lattices filling simple primitives.

Every builder places particles on a regular square (2D) or cubic (3D) grid
of spacing ``dx`` and returns their positions as an ``(n, 3)`` float64 array
in metres; in 2D (plane strain) the third column is exactly zero. The nominal
volume of every particle is ``dx**dim`` (m^3, or m^2 per unit depth in 2D);
it is *not* returned, callers compute it from ``dx`` and ``dim``.

Ordering is deterministic: particles are sorted lexicographically by their
integer grid index ``(i_x, i_y, i_z)`` along the global axes, ``i_x`` slowest
(``numpy.meshgrid(..., indexing="ij")`` order), whatever the primitive's
axis.

Grids are symmetric about the primitive's centre: along an axis with ``n``
points the offsets from the centre are ``(i - (n - 1) / 2) * dx``, i.e. the
points are cell centres of ``n`` cells of width ``dx`` centred on the centre.
Counts ``n`` are ``round(extent / dx)`` rounded half up, at least 1.

Curved primitives (cylinder, ring) use a grid-based, not radial, lattice, as
in Hušek et al. (2017); which grid points belong to the cross-section is set
by the ``rule`` keyword (see :data:`RULES`).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping

import numpy as np

__all__ = [
    "RULES",
    "SHAPES",
    "box_lattice",
    "cylinder_lattice",
    "ring_lattice",
    "rotate_about",
    "sphere_lattice",
    "prism_lattice",
    "points_lattice",
    "read_point_table",
    "read_points",
    "ogive_lattice",
    "ogive_nose_length",
    "ogive_profile",
    "ogive_volume",
    "polygon_area",
    "polygon_contains",
    "lattice_from_shape",
]

#: Inclusion rules for the cross-section of :func:`cylinder_lattice` and
#: :func:`ring_lattice`. ``d`` is the distance of a grid point from the axis,
#: ``d_min`` / ``d_max`` the smallest / largest distance from the axis of any
#: point of the point's ``dx x dx`` cross-section cell.
RULES = {
    "centre": "the point itself lies in the cross-section: inner < d <= outer",
    "cell_overlap": "its cell overlaps the cross-section: d_min < outer and d_max > inner",
    "cell_inside": "its whole cell lies in the cross-section: d_min >= inner and d_max <= outer",
}

_AXIS_NAMES = {"x": 0, "y": 1, "z": 2}

# Relative tolerance of all inclusion tests (points on a boundary are kept).
_RTOL = 1e-9


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------
def _check_dim(dim: int, one: bool = False) -> int:
    """``dim`` as an int: 2 or 3, or also 1 (a segment along x) if ``one``."""
    if dim not in ((1, 2, 3) if one else (2, 3)):
        raise ValueError(f"dim must be {'1, ' if one else ''}2 or 3, got {dim!r}")
    return int(dim)


def _positive(name: str, value: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number, got {value!r}") from None
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return value


def _point(p, dim: int, name: str) -> np.ndarray:
    """Coerce a point to a (3,) float64 array; in 2D keep x, y and set z = 0."""
    a = np.asarray(p, dtype=np.float64).reshape(-1)
    allowed = {1: (1, 2, 3), 2: (2, 3)}.get(dim, (3,))
    if a.size not in allowed:
        raise ValueError(f"{name} must have {' or '.join(map(str, allowed))} "
                         f"components in {dim}D, got {a.size}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {a}")
    out = np.zeros(3)
    out[:dim] = a[:dim]
    return out


def axis_index(axis) -> int:
    """Axis name ("x", "y", "z", any case) or index (0, 1, 2) -> index."""
    if isinstance(axis, str) and axis.lower() in _AXIS_NAMES:
        return _AXIS_NAMES[axis.lower()]
    if isinstance(axis, (int, np.integer)) and not isinstance(axis, bool) and 0 <= axis <= 2:
        return int(axis)
    raise ValueError(f"axis must be one of 'x', 'y', 'z' (or 0, 1, 2), got {axis!r}")


def _count(extent: float, dx: float) -> int:
    """Number of cells of width dx across extent: round half up, at least 1."""
    return max(1, int(np.floor(extent / dx + 0.5)))


def _offsets(n: int, dx: float) -> np.ndarray:
    """(n,) offsets (i - (n-1)/2) dx of n cell centres centred on zero [m]."""
    return (np.arange(n) - 0.5 * (n - 1)) * dx


def _grid(offsets: list[np.ndarray]) -> np.ndarray:
    """(n, 3) tensor-product grid of three offset vectors, ``ij`` order."""
    mesh = np.meshgrid(*offsets, indexing="ij")
    return np.stack([m.reshape(-1) for m in mesh], axis=1)


# --------------------------------------------------------------------------
# builders
# --------------------------------------------------------------------------
def box_lattice(lo, hi, dx: float, dim: int) -> np.ndarray:
    """Particles filling an axis-aligned box.

    Parameters
    ----------
    lo, hi : array_like, (3,) or (2,) in 2D or (1,) in 1D
        Opposite corners [m], ``hi >= lo``; in 2D only x and y are used, in
        1D only x (a segment).
    dx : float
        Particle spacing [m].
    dim : {1, 2, 3}
        Spatial dimension.

    Returns
    -------
    x : (n, 3) float64
        Positions [m]; ``n = prod(n_a)`` with ``n_a = max(1, round((hi_a -
        lo_a) / dx))`` per axis. The points are cell centres, centred in the
        box; when the box is not a whole number of ``dx`` long the lattice
        overhangs or falls short equally at both ends. Nominal volume per
        particle ``dx**dim``.
    """
    dim = _check_dim(dim, one=True)
    dx = _positive("dx", dx)
    lo, hi = _point(lo, dim, "lo"), _point(hi, dim, "hi")
    if np.any(hi < lo):
        raise ValueError(f"box hi must be >= lo, got lo={lo[:dim]}, hi={hi[:dim]}")
    offsets = [_offsets(_count(hi[a] - lo[a], dx), dx) if a < dim else np.zeros(1)
               for a in range(3)]
    return 0.5 * (lo + hi) + _grid(offsets)


def _radial_lattice(centre, inner: float, outer: float, length, axis, dx: float,
                    dim: int, rule: str) -> np.ndarray:
    """Shared body of :func:`cylinder_lattice` and :func:`ring_lattice`."""
    dim = _check_dim(dim)
    dx = _positive("dx", dx)
    if rule not in RULES:
        raise ValueError(f"rule must be one of {sorted(RULES)}, got {rule!r}")
    c = _point(centre, dim, "centre")
    ax = axis_index(axis)
    if dim == 2:
        if ax != 2:
            raise ValueError(f"in 2D the axis must be 'z' (a disc in the x-y plane), got {axis!r}")
        n_layers = 1
    else:
        n_layers = _count(_positive("length", length), dx)

    n = _count(2.0 * outer, dx)
    offsets = [_offsets(n, dx) for _ in range(3)]
    offsets[ax] = _offsets(n_layers, dx)
    rel = _grid(offsets)

    perp = [a for a in range(3) if a != ax]
    u, v = np.abs(rel[:, perp[0]]), np.abs(rel[:, perp[1]])
    tol = _RTOL * max(outer, dx)
    if rule == "centre":
        d = np.hypot(u, v)
        keep = (d > inner + tol) & (d <= outer + tol)
    else:
        h = 0.5 * dx
        d_min = np.hypot(np.maximum(u - h, 0.0), np.maximum(v - h, 0.0))
        d_max = np.hypot(u + h, v + h)
        if rule == "cell_overlap":
            keep = (d_min < outer - tol) & (d_max > inner + tol)
        else:  # cell_inside
            keep = (d_min >= inner - tol) & (d_max <= outer + tol)
    return c + rel[keep]


def rotate_about(x, centre, axis, degrees: float) -> np.ndarray:
    """Points ``x`` (n, 3) [m] rotated by ``degrees`` about the line through
    ``centre`` (3,) along ``axis`` ("x", "y", "z" or 0, 1, 2), right-handed
    (a new array)."""
    a = axis_index(axis)
    u, v = [k for k in range(3) if k != a]
    if a == 1:  # right-handed about y: z -> x
        u, v = v, u
    t = np.radians(float(degrees))
    c, s = np.cos(t), np.sin(t)
    rel = np.asarray(x, float) - np.asarray(centre, float)
    out = rel.copy()
    out[:, u] = c * rel[:, u] - s * rel[:, v]
    out[:, v] = s * rel[:, u] + c * rel[:, v]
    return out + np.asarray(centre, float)


def cylinder_lattice(centre, radius: float, length, axis, dx: float, dim: int,
                     *, rule: str = "centre", tilt: float | None = None,
                     tilt_axis="y") -> np.ndarray:
    """Particles filling a solid circular cylinder (a disc in 2D).

    The lattice is grid based (not radial), as for the concrete disc of
    Hušek et al. (2017): ``n = round(2 radius / dx)`` grid points across,
    symmetric about the axis; the points kept are chosen by ``rule``.

    Parameters
    ----------
    centre : array_like, (3,) or (2,) in 2D
        Centre of the cylinder [m] (middle of its length in 3D).
    radius : float
        Radius [m].
    length : float or None
        Length along the axis [m]; ``n_l = max(1, round(length / dx))``
        layers centred on ``centre``. Ignored in 2D (may be None).
    axis : {"x", "y", "z"} or {0, 1, 2}
        Cylinder axis; must be "z" in 2D.
    dx : float
        Particle spacing [m].
    dim : {2, 3}
        Spatial dimension.
    rule : {"centre", "cell_overlap", "cell_inside"}, optional
        Cross-section inclusion rule, see :data:`RULES`. The default
        "centre" keeps points with distance from the axis <= radius (plus a
        relative tolerance of 1e-9); it gives the paper's 1,264 particles per
        layer for 40 across (10,112 for 8 layers).
    tilt : float, optional
        3D: the lattice (cylinder and grid) rotated by this angle [degrees]
        about ``tilt_axis`` through ``centre`` (:func:`rotate_about`), e.g.
        a charge turned from upright.
    tilt_axis : {"x", "y", "z"}, optional

    Returns
    -------
    x : (n, 3) float64
        Positions [m], grid-index lexicographic order; nominal volume per
        particle ``dx**dim``.
    """
    radius = _positive("radius", radius)
    x = _radial_lattice(centre, -np.inf, radius, length, axis, dx, dim, rule)
    if tilt:
        if dim != 3:
            raise ValueError("tilt is for 3D cylinders only")
        x = rotate_about(x, _point(centre, dim, "centre"), tilt_axis, tilt)
    return x


def ring_lattice(centre, inner_radius: float, outer_radius: float, length, axis,
                 dx: float, dim: int, *, rule: str = "centre") -> np.ndarray:
    """Particles filling a hollow circular cylinder (an annulus in 2D).

    Same grid as :func:`cylinder_lattice` with ``radius = outer_radius``
    (``round(2 outer_radius / dx)`` points across); with the default rule
    the points kept satisfy ``inner_radius < distance <= outer_radius``.

    Parameters
    ----------
    centre : array_like, (3,) or (2,) in 2D
        Centre [m].
    inner_radius, outer_radius : float
        Radii [m], ``0 <= inner_radius < outer_radius``.
    length : float or None
        Length along the axis [m] (3D only, ignored in 2D).
    axis : {"x", "y", "z"} or {0, 1, 2}
        Ring axis; must be "z" in 2D.
    dx : float
        Particle spacing [m].
    dim : {2, 3}
        Spatial dimension.
    rule : {"centre", "cell_overlap", "cell_inside"}, optional
        Inclusion rule, see :data:`RULES`.

    Returns
    -------
    x : (n, 3) float64
        Positions [m]; nominal volume per particle ``dx**dim``.
    """
    outer = _positive("outer_radius", outer_radius)
    inner = float(inner_radius)
    if not (np.isfinite(inner) and 0.0 <= inner < outer):
        raise ValueError(f"need 0 <= inner_radius < outer_radius, got {inner!r}, {outer!r}")
    return _radial_lattice(centre, inner, outer, length, axis, dx, dim, rule)


def sphere_lattice(centre, radius: float, dx: float, dim: int) -> np.ndarray:
    """Particles filling a ball (a disc in the x-y plane in 2D).

    Parameters
    ----------
    centre : array_like, (3,) or (2,) in 2D
        Centre [m].
    radius : float
        Radius [m].
    dx : float
        Particle spacing [m].
    dim : {2, 3}
        Spatial dimension.

    Returns
    -------
    x : (n, 3) float64
        Grid points symmetric about the centre (``round(2 radius / dx)``
        across each axis) with ``|x - centre| <= radius`` (relative
        tolerance 1e-9); nominal volume per particle ``dx**dim``.
    """
    dim = _check_dim(dim)
    dx = _positive("dx", dx)
    radius = _positive("radius", radius)
    c = _point(centre, dim, "centre")
    n = _count(2.0 * radius, dx)
    rel = _grid([_offsets(n, dx) if a < dim else np.zeros(1) for a in range(3)])
    keep = np.linalg.norm(rel, axis=1) <= radius + _RTOL * max(radius, dx)
    return c + rel[keep]


#: In-plane coordinates of a prism's polygon for each axis (cyclic order, so
#: that a counter-clockwise polygon has its normal along +axis).
PRISM_PLANES = {0: (1, 2), 1: (2, 0), 2: (0, 1)}


def polygon_area(poly) -> float:
    """Signed area of the polygon ``poly`` (k, 2) [m^2] (shoelace formula;
    positive counter-clockwise)."""
    p = np.asarray(poly, dtype=np.float64)
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def polygon_contains(poly: np.ndarray, pts: np.ndarray, tol: float) -> np.ndarray:
    """Which of the points ``pts`` (n, 2) lie in the simple polygon ``poly``
    (k, 2), boundary within ``tol`` included: the even-odd ray-crossing rule
    (Shimrat 1962, Algorithm 112) plus a distance-to-edge test for points on
    an edge. Returns (n,) bool."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    x, y = pts[:, 0:1], pts[:, 1:2]
    ax, ay, bx, by = a[:, 0], a[:, 1], b[:, 0], b[:, 1]
    straddle = (ay > y) != (by > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = ax + (y - ay) * (bx - ax) / (by - ay)
    inside = (np.count_nonzero(straddle & (x < x_cross), axis=1) % 2) == 1
    e = b - a
    ll = np.maximum((e * e).sum(axis=1), 1e-300)
    t = np.clip(((x - ax) * e[:, 0] + (y - ay) * e[:, 1]) / ll, 0.0, 1.0)
    d2 = (x - (ax + t * e[:, 0])) ** 2 + (y - (ay + t * e[:, 1])) ** 2
    return inside | (d2.min(axis=1) <= tol * tol)


def prism_section(points, dim: int, axis, length) -> tuple[np.ndarray, int]:
    """A prism's polygon (k, 2) float64 and its axis index, checked: three or
    more [u, v] vertices; in 2D the axis "z" and no length."""
    poly = np.asarray(points, dtype=np.float64)
    if poly.ndim != 2 or poly.shape[1] != 2 or poly.shape[0] < 3:
        raise ValueError(f"points must be three or more [u, v] pairs, got shape {poly.shape}")
    ax = axis_index(axis)
    if dim == 2:
        if ax != 2:
            raise ValueError(f"in 2D the axis must be 'z' (a polygon in the x-y plane), "
                             f"got {axis!r}")
        if length is not None:
            raise ValueError("a prism in 2D takes no length")
    return poly, ax


def prism_lattice(points, dx: float, dim: int, axis="z", base: float = 0.0,
                  length=None) -> np.ndarray:
    """Particles filling a straight prism: a simple polygon extruded along an
    axis (the polygon itself in 2D). An L-specimen, an I- or T-section.

    Parameters
    ----------
    points : (k, 2) array_like, k >= 3
        Polygon vertices [m] in order (either sense), in the plane normal to
        ``axis``: (x, y) for "z", (y, z) for "x", (z, x) for "y"
        (:data:`PRISM_PLANES`).
    dx : float
        Particle spacing [m].
    dim : {2, 3}
        In 2D the axis must be "z" and ``length`` absent.
    axis : "x", "y" or "z"
        Extrusion direction.
    base, length : float
        3D: the prism spans ``[base, base + length]`` along the axis [m].

    Returns
    -------
    x : (n, 3) float64
        Cell centres of the grid of spacing ``dx`` centred on the polygon's
        bounding box (and on the extrusion) that lie in the polygon (points
        on its boundary, within 1e-9 of the size, kept). When the polygon's
        vertices sit on multiples of dx from its bounding box, every cell is
        wholly inside or outside and the volume is exact. Nominal volume per
        particle ``dx**dim``.
    """
    dim = _check_dim(dim)
    dx = _positive("dx", dx)
    poly, ax = prism_section(points, dim, axis, length)
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    offsets = [np.zeros(1), np.zeros(1), np.zeros(1)]
    pu, pv = PRISM_PLANES[ax]
    offsets[pu] = _offsets(_count(hi[0] - lo[0], dx), dx)
    offsets[pv] = _offsets(_count(hi[1] - lo[1], dx), dx)
    centre = np.zeros(3)
    centre[pu], centre[pv] = 0.5 * (lo + hi)
    if dim == 3:
        offsets[ax] = _offsets(_count(_positive("length", length), dx), dx)
        centre[ax] = float(base) + 0.5 * float(length)
    rel = _grid(offsets)
    x = centre + rel
    size = max(float(np.max(hi - lo)), dx)
    keep = polygon_contains(poly, x[:, [pu, pv]], _RTOL * size)
    return x[keep]


NOSES = ("+x", "-x", "+y", "-y", "+z", "-z")


def ogive_nose_length(radius: float, crh: float) -> float:
    """Length [m] of a tangent-ogive nose of shank radius ``radius`` [m] and
    calibre-radius-head ``crh`` (psi = s / (2 a), s the ogive's arc radius):
    ``l_n = a sqrt(4 psi - 1)`` (Forrestal et al. 1994's geometry)."""
    return float(radius) * np.sqrt(4.0 * float(crh) - 1.0)


def ogive_profile(zeta, radius: float, crh: float) -> np.ndarray:
    """Radius [m] of a tangent-ogive projectile at distance ``zeta`` [m] from
    its tip (array): ``r = sqrt(s^2 - (l_n - zeta)^2) - (s - a)`` on the nose
    (0 <= zeta <= l_n: 0 at the tip, ``a`` where the arc meets the shank
    tangentially), ``a`` behind it, with ``s = 2 psi a``; 0 ahead of the tip."""
    a, s = float(radius), 2.0 * float(crh) * float(radius)
    ln = ogive_nose_length(a, crh)
    z = np.asarray(zeta, float)
    nose = np.sqrt(np.maximum(s * s - (ln - np.clip(z, 0.0, ln)) ** 2, 0.0)) - (s - a)
    return np.where(z < 0.0, 0.0, np.where(z < ln, np.maximum(nose, 0.0), a))


def ogive_volume(radius: float, length: float, crh: float) -> float:
    """Volume [m^3] of the tangent-ogive projectile: the nose's
    ``pi int_0^l_n r(zeta)^2 dzeta`` (Gauss-Legendre, 64 points: exact to
    round-off for this smooth profile) and a cylinder behind it."""
    ln = ogive_nose_length(radius, crh)
    t, w = np.polynomial.legendre.leggauss(64)
    z = 0.5 * ln * (t + 1.0)
    nose = np.pi * 0.5 * ln * float(np.sum(w * ogive_profile(z, radius, crh) ** 2))
    return nose + np.pi * float(radius) ** 2 * (float(length) - ln)


def ogive_lattice(tip, radius: float, length: float, crh: float, dx: float, dim: int,
                  *, nose: str = "-z") -> np.ndarray:
    """Particles filling a projectile: a circular cylinder with a tangent-ogive
    nose (3D only), the shape of Forrestal et al.'s penetration tests.

    The grid is :func:`cylinder_lattice`'s (``round(2 radius / dx)`` points
    across, ``round(length / dx)`` layers) over the projectile's length; a
    point is kept when its distance from the axis is at most
    :func:`ogive_profile` at its distance from the tip.

    Parameters
    ----------
    tip : array_like, (3,)
        The nose's tip [m].
    radius : float
        Shank radius a [m].
    length : float
        Overall length from the tip to the tail [m], at least the nose's
        ``a sqrt(4 crh - 1)``.
    crh : float
        Calibre-radius-head psi >= 0.5 (0.5: a hemispherical nose).
    dx : float
        Particle spacing [m].
    dim : 3
    nose : {"+x", "-x", "+y", "-y", "+z", "-z"}
        The direction the nose points (the direction of flight).

    Returns
    -------
    x : (n, 3) float64
        Positions [m]; nominal volume per particle ``dx**3``.
    """
    if int(dim) != 3:
        raise ValueError("an ogive projectile is a 3D shape")
    if nose not in NOSES:
        raise ValueError(f"nose must be one of {', '.join(NOSES)}, got {nose!r}")
    a, length, crh = _positive("radius", radius), _positive("length", length), float(crh)
    if not (np.isfinite(crh) and crh >= 0.5):
        raise ValueError(f"crh must be at least 0.5 (a hemispherical nose), got {crh!r}")
    if ogive_nose_length(a, crh) > length * (1.0 + _RTOL):
        raise ValueError(f"the nose ({ogive_nose_length(a, crh):g} m long) is longer than "
                         f"the projectile ({length:g} m)")
    ax, sign = axis_index(nose[1]), (1.0 if nose[0] == "+" else -1.0)
    t = _point(tip, 3, "tip")
    centre = t.copy()
    centre[ax] -= sign * 0.5 * length
    x = _radial_lattice(centre, -np.inf, a, length, nose[1], dx, 3, "centre")
    zeta = sign * (t[ax] - x[:, ax])
    perp = [k for k in range(3) if k != ax]
    r = np.hypot(x[:, perp[0]] - t[perp[0]], x[:, perp[1]] - t[perp[1]])
    return x[r <= ogive_profile(zeta, a, crh) * (1.0 + _RTOL) + _RTOL * dx]


def read_point_table(path, dim: int, allowed=None, what: str = "row") -> dict:
    """The columns of a CSV table of points: a header row naming them, then
    one point per line (lines starting with ``#`` skipped). ``x, y`` (and
    ``z`` in 3D) are required; other columns must be among ``allowed``, or
    are any (``allowed`` None). Returns (P,) float arrays by column name.
    Raises :class:`ValueError` naming the file and the line: no header, a
    missing or unknown column, a value that is not a finite number, or no
    ``what`` after the header. The ``points`` body shape
    (:func:`read_points`) and ``[body.initial] file`` read through it.
    """
    import csv

    need = list("xyz"[:dim])
    with open(path, newline="") as f:
        lines = [(k, line) for k, line in enumerate(f, start=1)
                 if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no header line (it must name the columns "
                         f"{', '.join(need)})")
    rows = list(csv.reader(line for _, line in lines))
    header = [c.strip() for c in rows[0]]
    missing = [c for c in need if c not in header]
    if missing:
        any_of = f" and any of {', '.join(allowed)}" if allowed else ""
        raise ValueError(f"{path}: no column {', '.join(missing)}; the header must "
                         f"name {', '.join(need)}{any_of}")
    if allowed is not None:
        unknown = [c for c in header if c not in ("x", "y", "z", *allowed)]
        if unknown:
            raise ValueError(f"{path}: unknown column {', '.join(unknown)}; the columns "
                             f"are x, y, z, {', '.join(allowed)}")
    table = np.full((len(rows) - 1, len(header)), np.nan)
    for r, row in enumerate(rows[1:]):
        try:
            table[r] = [float(v) for v in row]
        except ValueError:
            pass  # reported below with its line
        if len(row) != len(header) or not np.isfinite(table[r]).all():
            raise ValueError(f"{path}, line {lines[r + 1][0]}: {row} is not "
                             f"{len(header)} finite numbers (columns "
                             f"{', '.join(header)})")
    if not table.shape[0]:
        raise ValueError(f"{path}: a header and no {what}")
    return {c: table[:, k] for k, c in enumerate(header)}


def read_points(file, dim: int, length_unit: float = 1.0) -> np.ndarray:
    """Positions of a ``points`` body (:func:`read_point_table`: columns
    ``x, y`` in 2D and ``x, y, z`` in 3D, others ignored), one particle per
    row, in units of ``length_unit`` [m]. Returns (n, 3) float64 [m],
    ``z = 0`` in 2D."""
    cols = read_point_table(file, dim, what="particle")
    x = np.zeros((cols["x"].shape[0], 3))
    for k, c in enumerate("xyz"[:dim]):
        x[:, k] = cols[c]
    return x * length_unit


def points_lattice(file, dx: float, dim: int, length_unit: float = 1.0) -> np.ndarray:
    """The ``points`` shape: the particles of a file (:func:`read_points`), each
    standing for the volume ``dx**dim`` as a lattice's would (LS-DYNA's
    ``*ELEMENT_SPH``, written by ``sphdyn import``)."""
    _positive("dx", dx)
    return read_points(file, dim, length_unit)


# --------------------------------------------------------------------------
# dispatch
# --------------------------------------------------------------------------
SHAPES = {
    "box": box_lattice,
    "cylinder": cylinder_lattice,
    "ring": ring_lattice,
    "sphere": sphere_lattice,
    "prism": prism_lattice,
    "ogive": ogive_lattice,
    "points": points_lattice,
}


def lattice_from_shape(shape: Mapping, dx: float, dim: int) -> np.ndarray:
    """Build the lattice described by a shape dictionary.

    Parameters
    ----------
    shape : mapping
        ``shape["shape"]`` is one of "box", "cylinder", "ring", "sphere",
        "prism";
        every other key is passed as a keyword argument to the matching
        builder (``lo``, ``hi``, ``centre``, ``radius``, ``length``,
        ``axis``, ``inner_radius``, ``outer_radius``, ``rule``, ``points``,
        ``base``). In 2D the
        cylinder and ring keys ``length`` and ``axis`` are optional
        (defaults None and "z"). Keys whose value is None are treated as
        absent (so a pydantic ``model_dump()`` can be passed directly).
    dx : float
        Particle spacing [m].
    dim : {2, 3}
        Spatial dimension.

    Returns
    -------
    x : (n, 3) float64
        Positions [m]; nominal volume per particle ``dx**dim``.

    Raises
    ------
    ValueError
        Unknown shape (the message names the valid ones), unknown or missing
        keys.
    """
    valid = ", ".join(SHAPES)
    if not isinstance(shape, Mapping) or "shape" not in shape:
        raise ValueError(f"shape must be a mapping with a 'shape' key (one of {valid})")
    kind = shape["shape"]
    if kind not in SHAPES:
        raise ValueError(f"unknown shape {kind!r}; valid shapes: {valid}")
    builder = SHAPES[kind]
    kwargs = {k: v for k, v in shape.items() if k != "shape" and v is not None}
    if dim == 2 and kind in ("cylinder", "ring"):
        kwargs.setdefault("length", None)
        kwargs.setdefault("axis", "z")

    params = inspect.signature(builder).parameters
    allowed = [p for p in params if p not in ("dx", "dim")]
    unknown = sorted(set(kwargs) - set(allowed))
    if unknown:
        raise ValueError(f"shape {kind!r} does not take {unknown}; allowed keys: {allowed}")
    missing = [p for p in allowed
               if params[p].default is inspect.Parameter.empty and p not in kwargs]
    if missing:
        raise ValueError(f"shape {kind!r} is missing {missing}")
    return builder(dx=dx, dim=dim, **kwargs)
