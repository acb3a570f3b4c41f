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


def sample(x, t, left, right, gamma, x0=0.0):
    """Density, velocity and pressure (each (n,)) at ``x`` (n,) and time ``t``."""
    (rl, ul, pl), (rr, ur, pr) = left, right
    ps, us = star_state(left, right, gamma)
    gm, gp = gamma - 1.0, gamma + 1.0
    out = np.empty((3, len(x)))
    for k, xi in enumerate(np.asarray(x, float)):
        s = (xi - x0) / t
        if s <= us:  # left of the contact
            rho, u, p, c = rl, ul, pl, math.sqrt(gamma * pl / rl)
            if ps > pl:  # left shock
                sl = ul - c * math.sqrt(gp / (2 * gamma) * ps / pl + gm / (2 * gamma))
                if s > sl:
                    rho = rl * (ps / pl + gm / gp) / (gm / gp * ps / pl + 1.0)
                    u, p = us, ps
            else:  # left rarefaction
                cs = c * (ps / pl) ** (gm / (2 * gamma))
                if s > us - cs:
                    rho, u, p = rl * (ps / pl) ** (1 / gamma), us, ps
                elif s > ul - c:
                    u = 2 / gp * (c + gm / 2 * ul + s)
                    cf = 2 / gp * (c + gm / 2 * (ul - s))
                    rho = rl * (cf / c) ** (2 / gm)
                    p = pl * (cf / c) ** (2 * gamma / gm)
        else:
            rho, u, p, c = rr, ur, pr, math.sqrt(gamma * pr / rr)
            if ps > pr:  # right shock
                sr = ur + c * math.sqrt(gp / (2 * gamma) * ps / pr + gm / (2 * gamma))
                if s < sr:
                    rho = rr * (ps / pr + gm / gp) / (gm / gp * ps / pr + 1.0)
                    u, p = us, ps
            else:  # right rarefaction
                cs = c * (ps / pr) ** (gm / (2 * gamma))
                if s < us + cs:
                    rho, u, p = rr * (ps / pr) ** (1 / gamma), us, ps
                elif s < ur + c:
                    u = 2 / gp * (-c + gm / 2 * ur + s)
                    cf = 2 / gp * (c - gm / 2 * (ur - s))
                    rho = rr * (cf / c) ** (2 / gm)
                    p = pr * (cf / c) ** (2 * gamma / gm)
        out[:, k] = rho, u, p
    return out


def shock_speed(left, right, gamma):
    """Speed of the right-moving shock [m/s] (the right state is shocked)."""
    (rr, ur, pr) = right
    ps, _ = star_state(left, right, gamma)
    c = math.sqrt(gamma * pr / rr)
    gm, gp = gamma - 1.0, gamma + 1.0
    return ur + c * math.sqrt(gp / (2 * gamma) * ps / pr + gm / (2 * gamma))
