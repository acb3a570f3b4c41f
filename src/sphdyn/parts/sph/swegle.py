r"""Swegle tensile-instability indicator.

Swegle, Hicks & Attaway (1995) showed by a von Neumann analysis of the
updated-Lagrangian ("Eulerian kernel") SPH momentum equation that a
perturbation grows exponentially, independently of time step and artificial
viscosity, when

.. math:: W''(r_{ij})\, \sigma_n > 0,

with :math:`W''` the second radial derivative of the kernel at the
neighbour distance and :math:`\sigma_n` the stress along the pair direction,
positive in tension (thesis eq. 2.3.1). For the cubic spline
:math:`W'' > 0` for :math:`q = r/h > 2/3`, so with the usual spacing
(:math:`q = \Delta x/h = 1/1.2 = 0.83` or :math:`1/1.5 = 0.67`) tension is
unstable and compression stable.

The per-particle indicator computed here is the fraction of the particle's
neighbour pairs that satisfy the criterion,

.. math::
    s_i = \frac{1}{N_i}\, \#\{ j : W''(r_{ij}, h_{ij})\, \sigma_{n,ij} > 0
          \ \text{and}\ |\sigma_{n,ij}| > \tau\, \sigma_{\mathrm{ref}} \},
    \qquad
    \sigma_{n,ij} = \mathbf n_{ij}^T \sigma_i\, \mathbf n_{ij},\quad
    \mathbf n_{ij} = \frac{\mathbf x_i - \mathbf x_j}{r_{ij}},

where :math:`N_i` counts the neighbours within the kernel support (zero-mass
neighbours excluded), :math:`\sigma_{\mathrm{ref}} = \max_k \|\sigma_k\|_F`
is the largest stress norm of the model and :math:`\tau` =
:data:`REL_STRESS_TOL` ignores pairs whose normal stress is round-off
compared with the loading. The threshold is at least
:data:`STRAIN_FLOOR` times the largest modulus :math:`\rho c^2`
(:func:`stress_tolerance`): before any load (a body in free flight, all
stresses round-off) nothing is flagged, where the relative test alone
flagged hundreds of particles of the disc at stresses of micropascals. :math:`s_i = 0`: no pair of the particle is in
the unstable regime; :math:`s_i = 1`: all are. A particle is counted as
*unstable* when :math:`s_i >` :data:`FLAG_FRACTION` (most of its pairs
unstable). The criterion says nothing about the growth *rate*, which scales
with :math:`\sqrt{|\sigma|/\rho}/h`; see ``docs/tensile-instability.md``.

References
----------
Swegle, J.W., Hicks, D.L., Attaway, S.W. (1995). Smoothed particle
    hydrodynamics stability analysis. J. Comput. Phys. 116, 123-134.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...kernels import d2wdq2, support_nb

__all__ = ["REL_STRESS_TOL", "FLAG_FRACTION", "STRAIN_FLOOR", "stress_scale",
           "stress_tolerance", "swegle_indicator",
           "count_unstable"]

#: Pairs with ``|sigma_n| <= REL_STRESS_TOL * max_k ||sigma_k||_F`` are not flagged.
REL_STRESS_TOL = 1e-3
#: A particle is unstable when more than this fraction of its pairs is flagged.
FLAG_FRACTION = 0.5
#: Pairs with ``|sigma_n| <= STRAIN_FLOOR * max_k rho_k c_k^2`` are not
#: flagged either: a stress of a strain of 1e-9 is round-off, not a load.
STRAIN_FLOOR = 1e-9


@njit(cache=True, error_model="numpy")
def stress_scale(sig, m):
    """Largest Frobenius norm ``max_k ||sigma_k||_F`` [Pa] over particles with ``m > 0``."""
    smax = 0.0
    for i in range(sig.shape[0]):
        if m[i] == 0.0:
            continue
        s = 0.0
        for a in range(3):
            for b in range(3):
                s += sig[i, a, b] * sig[i, a, b]
        if s > smax:
            smax = s
    return np.sqrt(smax)


@njit(cache=True, error_model="numpy")
def stress_tolerance(sig, m, rho, c):
    """The indicator's stress threshold [Pa]: ``max(REL_STRESS_TOL *
    max_k ||sigma_k||_F, STRAIN_FLOOR * max_k rho_k c_k^2)`` over particles
    with ``m > 0``; ``sig`` (N, 3, 3) [Pa], ``m`` (N,) [kg], ``rho`` (N,)
    [kg/m^3], ``c`` (N,) [m/s]."""
    modulus = 0.0
    for i in range(m.shape[0]):
        if m[i] != 0.0 and rho[i] * c[i] * c[i] > modulus:
            modulus = rho[i] * c[i] * c[i]
    return max(REL_STRESS_TOL * stress_scale(sig, m), STRAIN_FLOOR * modulus)


@njit(cache=True, error_model="numpy", parallel=True)
def swegle_indicator(x, m, h, sig, offsets, idx, kid, sigma, dim, support_scale, tol, out):
    r"""Fraction of unstable neighbour pairs per particle (Swegle et al. 1995).

    .. math::
        s_i = \frac{1}{N_i} \#\{ j : W''(r_{ij}, h_{ij})\,
              \mathbf n_{ij}^T \sigma_i \mathbf n_{ij} > 0,\
              |\mathbf n_{ij}^T \sigma_i \mathbf n_{ij}| > \mathrm{tol} \}

    with :math:`h_{ij} = \kappa (h_i + h_j)/2` as in the momentum pass.

    Parameters
    ----------
    x : (N, 3) positions [m].
    m, h : (N,) mass (zero-mass neighbours are skipped), smoothing length [m].
    sig : (N, 3, 3) Cauchy stress [Pa], tension positive.
    offsets, idx : CSR neighbour list.
    kid, sigma, dim, support_scale : kernel id, normalisation (only its sign
        matters, so it is unused), dimension, support scale kappa.
    tol : float, absolute stress threshold [Pa] below which a pair is not
        flagged (use ``REL_STRESS_TOL * stress_scale(sig, m)``).
    out : (N,) out, indicator in [0, 1] (0 for particles without neighbours).
    """
    n = x.shape[0]
    qmax = support_nb(kid)
    three = dim == 3
    for i in prange(n):
        total = 0
        bad = 0
        hi = h[i]
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            if m[j] == 0.0 or j == i:
                continue
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2] if three else 0.0
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            hij = support_scale * 0.5 * (hi + h[j])
            if r2 >= (qmax * hij) ** 2 or r2 == 0.0:
                continue
            total += 1
            sn = (sig[i, 0, 0] * d0 * d0 + sig[i, 1, 1] * d1 * d1
                  + sig[i, 2, 2] * d2 * d2
                  + 2.0 * (sig[i, 0, 1] * d0 * d1 + sig[i, 0, 2] * d0 * d2
                           + sig[i, 1, 2] * d1 * d2)) / r2
            if abs(sn) <= tol:
                continue
            # sign(W'') = sign(w''(q)): sigma_d / h^(d+2) > 0
            if d2wdq2(kid, np.sqrt(r2) / hij) * sn > 0.0:
                bad += 1
        out[i] = bad / total if total > 0 else 0.0


@njit(cache=True, error_model="numpy")
def count_unstable(s, m, threshold):
    """Number of particles with ``m > 0`` and indicator ``s > threshold``."""
    c = 0
    for i in range(s.shape[0]):
        if m[i] > 0.0 and s[i] > threshold:
            c += 1
    return c
