"""Exact solution of the Riemann problem of an ideal gas (Toro, *Riemann
Solvers and Numerical Methods for Fluid Dynamics*, 3rd ed. 2009, ch. 4):
the reference of the shock-tube example and tests.

States are ``(rho, u, p)`` [kg/m^3, m/s, Pa]; the star pressure solves
:math:`f_L(p) + f_R(p) + u_R - u_L = 0` (Toro eq. 4.5) with the shock or
rarefaction branch of each side (eqs. 4.6, 4.7), and :func:`sample` gives
the self-similar solution at ``(x - x0)/t`` (Toro sec. 4.5).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


def _f(p, rho, pk, gamma):
    """Toro's pressure function f_K(p) and the sound speed of side K."""
    c = math.sqrt(gamma * pk / rho)
    if p > pk:  # shock (Toro eq. 4.6)
        a = 2.0 / ((gamma + 1.0) * rho)
        b = (gamma - 1.0) / (gamma + 1.0) * pk
        return (p - pk) * math.sqrt(a / (p + b)), c
    return 2.0 * c / (gamma - 1.0) * ((p / pk) ** ((gamma - 1.0) / (2.0 * gamma)) - 1.0), c


def star_state(left, right, gamma):
    """``(p*, u*)`` of the star region; ``left``, ``right`` = (rho, u, p)."""
    (rl, ul, pl), (rr, ur, pr) = left, right

    def g(p):
        return _f(p, rl, pl, gamma)[0] + _f(p, rr, pr, gamma)[0] + ur - ul

    p = brentq(g, 1e-12 * max(pl, pr), 100.0 * max(pl, pr), xtol=1e-14, rtol=1e-14)
    u = 0.5 * (ul + ur) + 0.5 * (_f(p, rr, pr, gamma)[0] - _f(p, rl, pl, gamma)[0])
    return p, u


def _left_wave(s, state, ps, us, gamma):
    """``(rho, u, p)`` at ``s = x/t <= u*`` of the left wave (shock or
    rarefaction) from ``state`` = (rho, u, p) into the star state ``(ps, us)``
    (Toro sec. 4.5.1). The right wave is this one mirrored (x, u -> -x, -u)."""
    rho0, u0, p0 = state
    gm, gp = gamma - 1.0, gamma + 1.0
    c = math.sqrt(gamma * p0 / rho0)
    if ps > p0:  # shock, speed Toro eq. 4.52
        if s > u0 - c * math.sqrt(gp / (2 * gamma) * ps / p0 + gm / (2 * gamma)):
            return rho0 * (ps / p0 + gm / gp) / (gm / gp * ps / p0 + 1.0), us, ps
        return rho0, u0, p0
    if s > us - c * (ps / p0) ** (gm / (2 * gamma)):  # behind the rarefaction's tail
        return rho0 * (ps / p0) ** (1 / gamma), us, ps
    if s > u0 - c:  # inside the fan (Toro eq. 4.56)
        cf = 2 / gp * (c + gm / 2 * (u0 - s))
        return rho0 * (cf / c) ** (2 / gm), 2 / gp * (c + gm / 2 * u0 + s), \
            p0 * (cf / c) ** (2 * gamma / gm)
    return rho0, u0, p0


def sample(x, t, left, right, gamma, x0=0.0):
    """Density, velocity and pressure (each (n,)) at ``x`` (n,) and time ``t``."""
    ps, us = star_state(left, right, gamma)
    mirrored = (right[0], -right[1], right[2])
    out = np.empty((3, len(x)))
    for k, xi in enumerate(np.asarray(x, float)):
        s = (xi - x0) / t
        if s <= us:
            out[:, k] = _left_wave(s, left, ps, us, gamma)
        else:
            rho, u, p = _left_wave(-s, mirrored, ps, -us, gamma)
            out[:, k] = rho, -u, p
    return out


def shock_speed(left, right, gamma):
    """Speed of the right-moving shock [m/s] (the right state is shocked,
    Toro eq. 4.59)."""
    (rr, ur, pr) = right
    ps, _ = star_state(left, right, gamma)
    c = math.sqrt(gamma * pr / rr)
    gm, gp = gamma - 1.0, gamma + 1.0
    return ur + c * math.sqrt(gp / (2 * gamma) * ps / pr + gm / (2 * gamma))
