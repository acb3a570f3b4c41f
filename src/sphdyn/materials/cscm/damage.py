"""CSCM damage: transition between modes, softening parameters, logistic damage.

Brittle (tension) and ductile (compression) damage laws of notes sec.
1.9-1.10 and the largest principal value used for the brittle damage state
and erosion.
"""

import math

from numba import njit

DMAX = 0.999  # maximum damage in unconfined states [R] (notes sec. 1.9)


@njit(cache=True, error_model="numpy", inline="always")
def power(x, e):
    """``x ** e``, with ``e == 1`` (the default ``pwrt`` and ``repow``) taken
    without a ``pow()`` call: the same bits, since ``pow`` is within 0.52 ulp
    (glibc) of the exact result ``x``, which is representable."""
    return x if e == 1.0 else x ** e


@njit(cache=True, error_model="numpy")
def transition(J1, r, pwr):
    """``trans = (|J1| / sqrt(3 J2'))^pwr`` clipped to [0, 1] (notes sec. 1.10 [R]).

    1 in uniaxial stress, 0 in pure shear; 1 if ``J2' = 0``.
    """
    if r <= 0.0:
        return 1.0
    x = abs(J1) / (math.sqrt(3.0) * r)
    if x >= 1.0:
        return 1.0
    return power(x, pwr)


@njit(cache=True, error_model="numpy")
def brittle_softening_c(r0t, size, gf, D):
    """Brittle softening parameter ``C = r0t L (1+D) ln(1+D) / (D GF)``.

    Derived so that ``L * integral(sigma d eps)`` after the peak of a
    uniaxial tension test equals ``GF`` (notes sec. 1.10 [D]; same closed
    form in Novozhilov's CapModel.py [S]). Units 1/sqrt(Pa).
    """
    return r0t * size * (1.0 + D) * math.log(1.0 + D) / (D * gf)


@njit(cache=True, error_model="numpy")
def ductile_softening_a(r0c, size, gf, B, li2mb):
    """Ductile softening parameter ``A`` (positive root of the quadratic).

    .. math:: G_F A^2 - \\frac{4L(1+B) r_{0c}\\ln(1+B)}{B} A
              + \\frac{4L(1+B)\\,\\mathrm{Li}_2(-B)}{B} = 0

    notes sec. 1.10 [D] (uniaxial compression, perfectly plastic undamaged
    stress after the peak, ``tau_c = sqrt(fc eps/2)``). Units 1/sqrt(Pa).
    """
    bq = 4.0 * size * (1.0 + B) * r0c * math.log(1.0 + B) / B
    cq = 4.0 * size * (1.0 + B) * li2mb / B
    return (bq + math.sqrt(bq * bq - 4.0 * gf * cq)) / (2.0 * gf)


@njit(cache=True, error_model="numpy")
def logistic_damage(tau, r0, rate, shape, dmax):
    """``d = (dmax/S) [(1 + S)/(1 + S exp(-k (tau - r0))) - 1]`` for tau > r0.

    Brittle (``S = D``, ``k = C``) and ductile (``S = B``, ``k = A``) laws of
    notes sec. 1.9 [R] (same forms in Novozhilov's CapModel.py [S]).
    """
    if tau <= r0:
        return 0.0
    return dmax / shape * ((1.0 + shape) / (1.0 + shape * math.exp(-rate * (tau - r0))) - 1.0)


@njit(cache=True, error_model="numpy")
def _mean_and_j2(e):
    """Mean ``m``, deviator diagonal ``d0, d1, d2`` and ``J2`` of a symmetric 6-tuple."""
    m = (e[0] + e[1] + e[2]) / 3.0
    d0 = e[0] - m
    d1 = e[1] - m
    d2 = e[2] - m
    j2 = (0.5 * (d0 * d0 + d1 * d1 + d2 * d2)
          + e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
    return m, d0, d1, d2, j2


@njit(cache=True, error_model="numpy")
def max_principal(e):
    """Largest eigenvalue of a symmetric 6-tuple (trigonometric formula):
    ``m + 2 sqrt(J2/3) cos(pi/6 - theta)``, ``sin(3 theta) = (3 sqrt(3)/2)
    J3 / J2^(3/2)``."""
    m, d0, d1, d2, j2 = _mean_and_j2(e)
    if j2 <= 1e-300:
        return m
    j3 = (d0 * (d1 * d2 - e[4] * e[4]) - e[3] * (e[3] * d2 - e[4] * e[5])
          + e[5] * (e[3] * e[4] - d1 * e[5]))
    x = 1.5 * math.sqrt(3.0) * j3 / (j2 * math.sqrt(j2))  # j2^(3/2) without a pow()
    x = min(1.0, max(-1.0, x))
    th = math.asin(x) / 3.0   # in [-pi/6, pi/6]; largest eigenvalue:
    return m + 2.0 * math.sqrt(j2 / 3.0) * math.cos(math.pi / 6.0 - th)


@njit(cache=True, error_model="numpy")
def max_principal_bound(e):
    """``m + 2 sqrt(J2/3)``, a bound of :func:`max_principal` without its
    ``asin`` and ``cos``: the same ``m`` and ``2 sqrt(J2/3)``, times
    ``cos(...) <= 1`` there, so in floating point too
    ``max_principal(e) <= max_principal_bound(e)`` (rounding is monotone)."""
    m, _, _, _, j2 = _mean_and_j2(e)
    return m + 2.0 * math.sqrt(j2 / 3.0)
