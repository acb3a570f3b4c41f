"""Initial velocity and stress fields of a body (``[body.initial]``).

A body's particles get, at t = 0, a velocity and (for incremental materials
in updated-Lagrangian bodies) a Cauchy stress that vary with position, from
expressions of x, y, z (:mod:`sphdyn.deck.expressions`) or a CSV file of
points. This is how a cantilever is released with its first mode's velocity
profile, or a column starts under its own weight, without the Python API.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..deck.expressions import ExpressionError, evaluate
from ..geometry.lattice import read_point_table

#: the stress component names and their (row, column) in the 3x3 tensor
COMPONENTS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "xz": (0, 2),
              "yz": (1, 2)}


def read_points(path: Path, dim: int) -> dict[str, np.ndarray]:
    """The columns of a ``[body.initial] file``: a CSV with a header row
    (:func:`~sphdyn.geometry.lattice.read_point_table`). Needs ``x``, ``y``
    (and ``z`` in 3D); other columns from ``vx, vy, vz, sxx, syy, szz, sxy,
    sxz, syz``. Returns arrays of shape (P,) by name.
    """
    from ..deck.sections.bodies import FILE_COLUMNS

    return read_point_table(path, dim, allowed=FILE_COLUMNS, what="point")


def interpolate(points: np.ndarray, values: np.ndarray, x: np.ndarray, how: str,
                max_distance: float, where: str) -> np.ndarray:
    """Values (P, k) at ``points`` (P, d) carried to particle positions ``x`` (N, d).

    ``how`` = "nearest": the nearest point, which must lie within
    ``max_distance`` [m]; "linear": barycentric interpolation on the Delaunay
    triangulation of the points (scipy), every particle inside it.
    """
    from scipy.interpolate import LinearNDInterpolator
    from scipy.spatial import cKDTree

    if how == "nearest":
        dist, k = cKDTree(points).query(x)
        far = np.flatnonzero(dist > max_distance)
        if far.size:
            i = far[np.argmax(dist[far])]
            raise ValueError(f"{where}: {far.size} particles are farther than "
                             f"{max_distance:.4g} m from every point of the file (the "
                             f"farthest {dist[i]:.4g} m, at {np.round(x[i], 6)}); give "
                             "points over the whole body or a larger max_distance")
        return values[k]
    try:
        out = LinearNDInterpolator(points, values)(x)
    except Exception as exc:  # scipy's Qhull errors: too few or flat points
        raise ValueError(f"{where}: the file's points cannot be triangulated "
                         f"({type(exc).__name__}); use interpolation = \"nearest\"") \
            from None
    out = np.asarray(out).reshape(x.shape[0], -1)
    outside = np.flatnonzero(~np.all(np.isfinite(out), axis=1))
    if outside.size:
        raise ValueError(f"{where}: {outside.size} particles lie outside the "
                         f"triangulation of the file's points (first at "
                         f"{np.round(x[outside[0]], 6)}); cover the body or use "
                         "interpolation = \"nearest\"")
    return out


def initial_fields(spec, x: np.ndarray, dim: int, dx: float, where: str
                   ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Velocity (N, 3) [m/s] and Cauchy stress (N, 3, 3) [Pa] of ``[body.initial]``.

    ``spec`` is the validated table, ``x`` (N, 3) the body's particle
    positions [m]; either result is None when the table does not give it.
    ``where`` names the table in messages. Raises ``ValueError``.
    """
    n = x.shape[0]
    vel = sig = None
    try:
        if spec.velocity is not None:
            vel = np.stack([evaluate(e, x) for e in spec.velocity], axis=1)
        if spec.stress is not None:
            sig = np.zeros((n, 3, 3))
            for comp, text in spec.stress.items():
                i, j = COMPONENTS[comp]
                sig[:, i, j] = sig[:, j, i] = evaluate(text, x)
    except ExpressionError as exc:
        raise ValueError(f"{where}: {exc}") from None
    if spec.file is not None:
        cols = read_points(spec.file, dim)
        given = [c for c in ("vx", "vy", "vz") if c in cols]
        if given and vel is not None:
            raise ValueError(f"{where}: velocity is given twice (expressions and the "
                             f"file's {', '.join(given)}); keep one")
        stress_cols = [c for c in cols if c.startswith("s")]
        if stress_cols and sig is not None:
            raise ValueError(f"{where}: stress is given twice (expressions and the "
                             f"file's {', '.join(stress_cols)}); keep one")
        names = given + stress_cols
        if not names:
            raise ValueError(f"{where}: the file {spec.file} has only coordinates; "
                             "add columns vx, vy, vz or sxx, ... (SI)")
        pts = np.stack([cols[c] for c in ("x", "y", "z")[:dim]], axis=1)
        vals = interpolate(pts, np.stack([cols[c] for c in names], axis=1),
                           x[:, :dim], spec.interpolation,
                           spec.max_distance or dx, where)
        got = dict(zip(names, vals.T))
        if given:
            vel = np.stack([got.get(c, np.zeros(n)) for c in ("vx", "vy", "vz")], axis=1)
        if stress_cols:
            sig = np.zeros((n, 3, 3))
            for c in stress_cols:
                i, j = COMPONENTS[c[1:]]
                sig[:, i, j] = sig[:, j, i] = got[c]
    if dim == 2 and vel is not None and np.any(vel[:, 2] != 0.0):
        raise ValueError(f"{where}: a 2D body cannot move in z; make the third "
                         "velocity 0 (or give two)")
    if dim == 2 and sig is not None and np.any(sig[:, [0, 1], 2] != 0.0):
        raise ValueError(f"{where}: xz and yz stresses mean nothing in a 2D deck "
                         "(plane strain); leave them out")
    return vel, sig
