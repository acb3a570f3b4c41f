r"""Lighting times of high explosives from the deck's [[detonation]] points.

A particle at :math:`\mathbf x` of an explosive with detonation velocity
``D`` is lit at

.. math:: t_l(\mathbf x) = \min_k \Big(t_k + \frac{|\mathbf x - \mathbf p_k|}{D}\Big)

over the points :math:`\mathbf p_k` (detonation times :math:`t_k`) that light
its material: the straight-line (Huygens without shadowing) lighting of
LS-DYNA's programmed burn. The explosive's burn clock starts at
:math:`-t_l` (:mod:`sphdyn.materials.explosive`).
"""

from __future__ import annotations

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..geometry.lattice import rotate_about
from ..materials.explosive import H_CLOCK, detonation_velocity, lit


def lighting_times(x: np.ndarray, points: np.ndarray, times: np.ndarray,
                   D: float) -> np.ndarray:
    """``t_l`` (n,) [s] of positions ``x`` (n, 3) [m] from detonation ``points``
    (k, 3) [m] at ``times`` (k,) [s] with detonation velocity ``D`` [m/s]
    (module docstring)."""
    t = np.full(x.shape[0], np.inf)
    for p, t0 in zip(points, times):
        t = np.minimum(t, t0 + np.linalg.norm(x - p, axis=1) / D)
    return t


def _turned(deck, det):
    """The detonation with its point turned with its ``rotate_with`` body's tilt."""
    if det.rotate_with is None:
        return det
    g = next(b for b in deck.body if b.name == det.rotate_with).geometry
    if not getattr(g, "tilt", None):
        return det
    point = rotate_about(np.asarray([det.point], float), g.centre, g.tilt_axis, g.tilt)[0]
    return det.model_copy(update={"point": tuple(float(c) for c in point)})


def light_explosives(deck, particles, groups) -> None:
    """Set the burn clock ``-t_l`` of every lit explosive's particles.

    Raises :class:`~sphdyn.deck.DeckError` naming ``detonation[k].point`` if
    a point is not in a charge it lights: farther than one particle spacing
    from every particle of those materials.
    """
    dets = [_turned(deck, d) for d in deck.detonation]
    if not dets:
        return
    spacing = particles.vol0 ** (1.0 / particles.dim)
    he = {g.material for g in groups if g.model.explosive}
    for k, d in enumerate(dets):
        mats = he if d.material is None else {
            next(i for i, m in enumerate(deck.material) if m.name == d.material)}
        sel = np.flatnonzero(np.isin(particles.mat, list(mats)))
        dist = np.linalg.norm(particles.x[sel] - np.asarray(d.point), axis=1)
        if not sel.size or np.min(dist - spacing[sel]) > 0.0:
            names = ", ".join(sorted(deck.material[i].name for i in mats))
            near = "" if not sel.size else f"; the nearest particle is {dist.min():.4g} m away"
            raise DeckError([format_problem(
                f"detonation[{k}].point", f"{list(d.point)} is not in the charge "
                f"({names}){near}", "place the point inside the explosive's body")])
    for g in groups:
        if not g.model.explosive or not lit(g.params) or not g.idx.size:
            continue
        name = deck.material[g.material].name
        ks = [k for k, d in enumerate(dets) if d.material in (None, name)]
        pts = np.array([dets[k].point for k in ks], float).reshape(-1, 3)
        t_l = lighting_times(particles.x[g.idx], pts, np.array([dets[k].time for k in ks]),
                             detonation_velocity(g.params))
        particles.hist[g.idx, g.column + H_CLOCK] = -t_l
