r"""Initial cracks as zero-mass particles (Hušek et al. 2017, sec. 5.2).

Two neighbouring SPH particles cannot be separated numerically, so a crack
is not cut into the lattice: the particles on the crack surface keep their
places but get zero mass. In the particle approximation (paper eq. 6) their
volume :math:`V_j = m_j/\rho_j` is zero, so they add nothing to any sum: the
kernel sums of their neighbours drop across the crack, a singularity that
the material feels as an initial weakening (paper Figs. 11-13).

In the solver a zero-mass particle exerts no force and carries no momentum
or energy, but it still moves: its acceleration is the SPH momentum sum
evaluated at its position (a per-unit-mass quantity that does not contain
its own mass), its velocity gradient, density and stress follow its
neighbours, so it travels with the material around it as an interpolation
point. The wall contact must then use the bulk-modulus stiffness (paper
eq. 9), because the mass-based spring of eq. 8 vanishes with the mass; see
:mod:`sphdyn.interactions.wall_contact`.

Crack shapes (``shape`` of a ``[[body.crack]]`` table), each thickened to
``rows`` particle rows, i.e. the particles whose centre lies closer than
:math:`\tfrac12\,\text{rows}\,\Delta x` to the crack surface:

* ``plane``: the plane through ``point`` with ``normal``, optionally limited
  to the points within ``radius`` of ``point`` (a penny crack in 3D, a
  segment of length 2 radius in 2D);
* ``polyline``: the segments joining ``points`` (in the plane normal to
  ``axis``), extruded through the body along ``axis`` (``z``: through the
  depth of a 3D disc; a line in 2D);
* ``box``: every particle inside the axis-aligned box ``lo``-``hi``
  (pre-fractured material).

A surface running through a row of lattice points and ``rows = 1`` selects
that row; a surface midway between two rows needs ``rows = 2``. A crack
selecting no particle is an error (it would silently do nothing).
"""

from __future__ import annotations

import numpy as np

__all__ = ["crack_mask", "crack_particles", "distance_to_polyline"]

_AXES = {"x": 0, "y": 1, "z": 2}
#: Relative tolerance on the half-thickness: a particle exactly at half a
#: spacing times rows from the surface (a lattice tie) is not selected.
_TIE = 1e-9


def distance_to_polyline(p: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Distance (N,) of points ``p`` (N, k) to the polyline through ``points`` (M, k)."""
    best = np.full(p.shape[0], np.inf)
    for a, b in zip(points[:-1], points[1:]):
        ab = b - a
        L2 = float(ab @ ab)
        t = np.zeros(p.shape[0]) if L2 == 0.0 else np.clip((p - a) @ ab / L2, 0.0, 1.0)
        d = np.linalg.norm(p - (a + t[:, None] * ab), axis=1)
        best = np.minimum(best, d)
    return best


def crack_particles(x: np.ndarray, crack: dict, dx: float) -> np.ndarray:
    """Particles (N,) bool of one crack ``crack`` (a ``[[body.crack]]`` dict).

    ``x`` (N, 3) initial positions [m], ``dx`` the body's particle spacing [m].
    """
    shape = crack["shape"]
    if shape == "box":
        lo = np.asarray(crack["lo"], float)
        hi = np.asarray(crack["hi"], float)
        return np.all((x >= lo) & (x <= hi), axis=1)
    half = 0.5 * crack["rows"] * dx * (1.0 - _TIE)
    if shape == "plane":
        n = np.asarray(crack["normal"], float)
        n = n / np.linalg.norm(n)
        r = x - np.asarray(crack["point"], float)
        dist = r @ n
        sel = np.abs(dist) < half
        if crack.get("radius") is not None:
            inplane = r - dist[:, None] * n
            sel &= np.linalg.norm(inplane, axis=1) <= crack["radius"]
        return sel
    if shape == "polyline":
        keep = [k for k in range(3) if k != _AXES[crack.get("axis", "z")]]
        pts = np.asarray(crack["points"], float)[:, keep]
        return distance_to_polyline(x[:, keep], pts) < half
    raise ValueError(f"unknown crack shape {shape!r}; use plane, polyline or box")


def crack_mask(x: np.ndarray, cracks, dx: float, body: str = "body") -> np.ndarray:
    """Union (N,) bool of the particles of all ``cracks`` of one body.

    Raises
    ------
    ValueError
        If a crack selects no particle, naming the body and the crack.
    """
    mask = np.zeros(x.shape[0], bool)
    for k, crack in enumerate(cracks or ()):
        sel = crack_particles(x, crack, dx)
        if not sel.any():
            raise ValueError(
                f"body {body!r}: crack {k} ({crack['shape']}) selects no particle; "
                "place it on a particle row, increase rows, or move it into the body")
        mask |= sel
    return mask
