"""Named independent estimates a comparison falls back to where measured data
are missing (docs/validation.md, "Missing"). They are estimates, not data:
the validation table marks them so.
"""

from __future__ import annotations

import math


def ndrc_depth(velocity: float, mass: float, diameter: float, fc: float,
               nose: float) -> float:
    """Modified NDRC penetration depth [m] of a rigid projectile into a
    concrete half-space (Kennedy 1976; quoted by UFC 3-340-02 and Li et al.
    2005), in its own units (M lb, d in, f'c psi, V ft/s)::

        G = 3.8e-5 N* M / (d sqrt(f'c)) (V / d)^1.8
        x / d = 2 sqrt(G)  for G <= 1,   x / d = G + 1  above.

    ``velocity`` [m/s], ``mass`` [kg], ``diameter`` [m], ``fc`` [Pa],
    ``nose`` the nose factor N* (0.72 for a flat nose).
    """
    lb, inch = mass / 0.45359237, diameter / 0.0254
    psi, fps = fc / 6894.757, velocity / 0.3048
    g = 3.8e-5 * nose * lb / (inch * math.sqrt(psi)) * (fps / inch) ** 1.8
    ratio = 2.0 * math.sqrt(g) if g <= 1.0 else g + 1.0
    return ratio * diameter
