"""Named particle sets: indices of the particles inside a region.

A region is a dictionary with a ``"shape"`` key and shape parameters (SI
units, points as (3,) or, in 2D, (2,) sequences):

* ``{"shape": "box", "lo": ..., "hi": ...}`` -- axis-aligned, inclusive;
* ``{"shape": "sphere", "centre": ..., "radius": r}``;
* ``{"shape": "halfspace", "point": p, "normal": n}`` -- ``(x - p) . n >= 0``
  (``n`` need not be unit length);
* ``{"shape": "cylinder", "centre": c, "radius": r, "axis": a,
  "length": L}`` -- ``axis`` is "x", "y", "z", 0, 1, 2 or a direction
  vector; ``length`` (optional, default None = infinite) is centred on ``c``.

Boundaries are inclusive with the tolerance ``1e-9 * L``, ``L`` the larger
of the region's size and the diagonal of the particles' bounding box. Keys
whose value is None are treated as absent. In 2D
the z coordinates of the particles and of the region's points are ignored
(treated as 0), so a sphere becomes a disc and a cylinder along z a disc.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .lattice import axis_index, _check_dim, _point, _positive

__all__ = ["REGION_SHAPES", "bounding_box", "select"]

_RTOL = 1e-9

# shape -> (required keys, optional keys)
REGION_SHAPES = {
    "box": (("lo", "hi"), ()),
    "sphere": (("centre", "radius"), ()),
    "halfspace": (("point", "normal"), ()),
    "cylinder": (("centre", "radius", "axis"), ("length",)),
}


def _positions(x) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must have shape (n, 3), got {x.shape}")
    return x


def bounding_box(x) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box of a point set.

    Parameters
    ----------
    x : (n, 3) array_like
        Positions [m], ``n >= 1``.

    Returns
    -------
    lo, hi : (3,) float64
        Componentwise minimum and maximum [m].
    """
    x = _positions(x)
    if x.shape[0] == 0:
        raise ValueError("bounding_box of an empty point set")
    return x.min(axis=0), x.max(axis=0)


def _direction(axis, dim: int) -> np.ndarray:
    """Unit (3,) vector from an axis name/index or a direction vector."""
    if isinstance(axis, (str, int, np.integer)):
        d = np.zeros(3)
        d[axis_index(axis)] = 1.0
        return d
    d = np.asarray(axis, dtype=np.float64).reshape(-1)
    if d.size == 2:
        d = np.append(d, 0.0)
    if d.size != 3 or not np.all(np.isfinite(d)) or not np.any(d):
        raise ValueError(f"axis must be 'x', 'y', 'z', 0, 1, 2 or a nonzero vector, got {axis!r}")
    return d / np.linalg.norm(d)


def _box(x, p, dim, size):
    lo, hi = _point(p["lo"], dim, "lo"), _point(p["hi"], dim, "hi")
    if np.any(hi < lo):
        raise ValueError(f"box hi must be >= lo, got lo={lo[:dim]}, hi={hi[:dim]}")
    tol = _RTOL * max(size, np.linalg.norm(hi - lo))
    return np.all((x >= lo - tol) & (x <= hi + tol), axis=1)


def _sphere(x, p, dim, size):
    c = _point(p["centre"], dim, "centre")
    r = _positive("radius", p["radius"])
    return np.linalg.norm(x - c, axis=1) <= r + _RTOL * max(size, r)


def _halfspace(x, p, dim, size):
    q = _point(p["point"], dim, "point")
    n = _point(p["normal"], dim, "normal")
    norm = np.linalg.norm(n)
    if norm == 0.0:
        raise ValueError("halfspace normal must be nonzero (in the x-y plane in 2D)")
    return (x - q) @ (n / norm) >= -_RTOL * size


def _cylinder(x, p, dim, size):
    c = _point(p["centre"], dim, "centre")
    r = _positive("radius", p["radius"])
    a = _direction(p["axis"], dim)
    length = p.get("length")
    rel = x - c
    s = rel @ a
    keep = np.linalg.norm(rel - s[:, None] * a, axis=1) <= r + _RTOL * max(size, r)
    if length is not None:  # None (or absent) = infinitely long
        length = _positive("length", length)
        keep &= np.abs(s) <= 0.5 * length + _RTOL * max(size, length)
    return keep


_MASKS = {"box": _box, "sphere": _sphere, "halfspace": _halfspace, "cylinder": _cylinder}


def select(x, region: Mapping | None, dim: int) -> np.ndarray:
    """Indices of the particles inside a region.

    Parameters
    ----------
    x : (n, 3) array_like
        Positions [m].
    region : mapping or None
        Region dictionary (see the module docstring); None selects all.
    dim : {2, 3}
        Spatial dimension; in 2D z is ignored.

    Returns
    -------
    idx : (k,) int64
        Sorted indices into ``x``.

    Raises
    ------
    ValueError
        Unknown shape (the message names the valid ones), unknown or missing
        keys, invalid parameters.
    """
    dim = _check_dim(dim, one=True)
    x = _positions(x)
    if region is None:
        return np.arange(x.shape[0], dtype=np.int64)
    valid = ", ".join(REGION_SHAPES)
    if not isinstance(region, Mapping) or "shape" not in region:
        raise ValueError(f"region must be None or a mapping with a 'shape' key (one of {valid})")
    kind = region["shape"]
    if kind not in REGION_SHAPES:
        raise ValueError(f"unknown region shape {kind!r}; valid shapes: {valid}")
    required, optional = REGION_SHAPES[kind]
    params = {k: v for k, v in region.items() if k != "shape" and v is not None}
    unknown = sorted(set(params) - set(required) - set(optional))
    missing = [k for k in required if k not in params]
    if unknown or missing:
        raise ValueError(f"region {kind!r}: unknown keys {unknown}, missing keys {missing}; "
                         f"allowed: {list(required + optional)}")

    if dim < 3:  # 2D: z = 0; 1D: y = z = 0
        x = x.copy()
        x[:, dim:] = 0.0
    size = float(np.linalg.norm(np.ptp(x, axis=0))) if x.shape[0] else 0.0
    mask = _MASKS[kind](x, params, dim, size)
    return np.flatnonzero(mask).astype(np.int64)
