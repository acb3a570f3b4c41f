"""Named independent estimates a comparison falls back to where measured data
are missing (docs/validation.md, "Missing"). They are estimates, not data:
the validation table marks them so.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


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


def ogive_nose_factor(crh: float) -> float:
    """Nose factor N* of an ogive nose of calibre radius head ``crh`` = s/d
    (Forrestal et al. 1994; Li & Chen 2003, Eq. 3a)::

        N* = 1 / (3 psi) - 1 / (24 psi^2)

    (15/96 = 0.156 for crh 2)."""
    return 1.0 / (3.0 * crh) - 1.0 / (24.0 * crh * crh)


def forrestal_resistance_constant(fc: float) -> float:
    """Forrestal et al. (1994), Eq. (12): the target resistance S [-] of the
    cavity-expansion force law from the cylinder strength ``fc`` [Pa]::

        S = 82.6 (f'c / MPa)^-0.544

    (11.9 for 35.2 MPa; the paper's Table 2 gives 12 for that concrete)."""
    return 82.6 * (fc / 1e6) ** -0.544


def forrestal_penetration(depth, velocity: float, mass: float, diameter: float,
                          fc: float, density: float, nose: float, S: float,
                          k: float = 2.0):
    r"""Velocity [m/s] of a rigid projectile at each ``depth`` [m] (array) in a
    concrete half-space, and its final depth [m], by Forrestal et al.'s
    (1994) two-stage force law (Li & Chen 2003, Eqs. 12-15)::

        F = c x                                   x <= k d   (crater)
        F = (pi d^2 / 4) (S f'c + N* rho V^2)     x >  k d   (tunnel)

    with ``c`` from the force's continuity at x = k d; the tunnel's motion
    ``m V dV/dx = -F`` integrates to

    .. math:: V^2(x) = \left(V_1^2 + \frac{S f'_c}{N^*\rho}\right)
              e^{-2 A N^*\rho (x - kd) / m} - \frac{S f'_c}{N^*\rho},
              \qquad X = kd + \frac{m}{2 A N^* \rho}
              \ln\left(1 + \frac{N^*\rho V_1^2}{S f'_c}\right)

    (:math:`A = \pi d^2/4`, :math:`V_1` the velocity at kd). ``velocity``
    the striking velocity, ``mass`` [kg], ``diameter`` d [m], ``fc`` [Pa],
    ``density`` the target's [kg/m^3], ``nose`` N* (:func:`ogive_nose_factor`),
    ``S`` (:func:`forrestal_resistance_constant`), ``k`` the crater depth in
    calibres (2: Forrestal et al. 1994). Zero velocity beyond the final depth.
    Returns (V at each depth, X).
    """
    x = np.asarray(depth, dtype=float)
    A = 0.25 * math.pi * diameter * diameter
    kd = k * diameter
    static, inertia = S * fc, nose * density
    c = A * (static + inertia * velocity ** 2) / (kd * (1.0 + A * inertia * kd / mass))
    v1_sq = velocity ** 2 - c * kd * kd / mass
    if v1_sq <= 0.0:  # stops in the crater: m V0^2 / 2 = c X^2 / 2
        X = velocity * math.sqrt(mass / c)
        v_sq = velocity ** 2 - c * np.minimum(x, X) ** 2 / mass
    else:
        X = kd + mass / (2.0 * A * inertia) * math.log1p(inertia * v1_sq / static)
        crater = velocity ** 2 - c * np.minimum(x, kd) ** 2 / mass
        tunnel = ((v1_sq + static / inertia) * np.exp(-2.0 * A * inertia
                                                      * (np.minimum(x, X) - kd) / mass)
                  - static / inertia)
        v_sq = np.where(x <= kd, crater, tunnel)
    return np.sqrt(np.clip(v_sq, 0.0, None)), X


def parabola_rectangle(strain, fc: float, eps_c2: float = 2.0e-3, n: float = 2.0):
    """Concrete compressive stress [Pa] of the parabola-rectangle diagram
    (EN 1992-1-1, 3.1.7, Eq. 3.17), compression positive::

        sigma = fc [1 - (1 - eps / eps_c2)^n]   for 0 <= eps <= eps_c2
        sigma = fc                              for eps > eps_c2

    zero in tension (a cracked section). The code ends the diagram at the
    crushing strain eps_cu2 (3.5 per mille for fck <= 50 MPa); here it goes
    on at fc, and the caller reads the top fibre's strain to know whether a
    state lies beyond it (a crushed zone held at zero stress would make the
    neutral axis of ``rc_section_moment`` ambiguous). ``strain`` an array
    [-], ``fc`` the (mean) cylinder strength; the defaults are the code's
    values for fck <= 50 MPa.
    """
    eps = np.asarray(strain, dtype=float)
    return np.where(eps > 0.0, fc * (1.0 - (1.0 - np.clip(eps, 0.0, eps_c2) / eps_c2) ** n), 0.0)


def bilinear_steel(strain, E: float, fy: float, fu: float, eps_u: float):
    """Reinforcing steel stress [Pa], tension positive: elastic to the
    yield strain fy / E, then the straight line to the tensile strength
    ``fu`` at the ultimate strain ``eps_u`` (as EN 1992-1-1 Fig. 3.8's
    inclined branch drawn through the measured fy, fu and eps_u); the same
    in compression; held at fu beyond eps_u."""
    eps = np.asarray(strain, dtype=float)
    eps_y = fy / E
    a = np.abs(eps)
    plastic = fy + (fu - fy) * (np.minimum(a, eps_u) - eps_y) / (eps_u - eps_y)
    return np.sign(eps) * np.where(a <= eps_y, E * a, plastic)


def rc_section_moment(curvature: float, width: float, height: float, fc: float,
                      bars: list[tuple[float, float]], steel: dict,
                      layers: int = 2000, **concrete) -> tuple[float, float]:
    """Bending moment [N m] and neutral-axis depth [m] of a rectangular RC
    section at a curvature [1/m], sagging (compression on top): plane
    sections, the strain at depth y below the top face
    ``eps(y) = curvature (c - y)`` (compression positive), the neutral-axis
    depth c found from the axial balance

        int_0^h sigma_c(eps(y)) b dy - sum_i A_i sigma_s(-eps(y_i)) = 0
        (sigma_s tension positive),

    the concrete by ``parabola_rectangle`` (no tension: a cracked section),
    the bars (``bars``: (depth of the bar's centre below the top [m], area
    [m^2]) each) by ``bilinear_steel`` with ``steel`` = dict(E, fy, fu,
    eps_u) and the concrete they displace neglected. The moment is taken
    about the top face. ``layers`` midpoint slices integrate the concrete
    (the error is of order (h / layers)^2). ``concrete`` passes eps_c2,
    n to ``parabola_rectangle``. With the concrete force growing and the
    bars' tension falling as c grows, the balance has one root.
    """
    y = (np.arange(layers) + 0.5) * height / layers
    dy = height / layers
    depth = np.array([b[0] for b in bars])
    area = np.array([b[1] for b in bars])

    def forces(c):
        sc = parabola_rectangle(curvature * (c - y), fc, **concrete) * width * dy
        ss = bilinear_steel(curvature * (depth - c), **steel) * area  # tension +
        return sc, ss

    def axial(c):
        sc, ss = forces(c)
        return sc.sum() - ss.sum()

    c = brentq(axial, 1e-9 * height, height, xtol=1e-14 * height)
    sc, ss = forces(c)
    # moment about the top face of the compressive resultant and the bars'
    # tension: M = sum T_i y_i - sum C_j y_j (sagging positive)
    moment = float(np.dot(ss, depth) - np.dot(sc, y))
    return moment, c
