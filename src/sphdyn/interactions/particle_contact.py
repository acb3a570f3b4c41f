r"""Penalty contact between particles of different bodies.

Bodies discretised with the total-Lagrangian kernel never see each other
through the SPH sums (their neighbour lists are fixed in the reference
configuration), so they need a contact algorithm (thesis sec. 3.2). Two
particles of different bodies, one of them at least total-Lagrangian
(updated-Lagrangian bodies meet through the kernel), are in contact when their distance is below
:math:`d_{ij} = f_c (s_i + s_j)/2` with the particle size
:math:`s = V_0^{1/d}` and ``f_c`` the contact distance factor (1 = touching
cells). The pair force is a linear spring along the centre line,

.. math:: \mathbf f_{ij} = k_{ij}\, (d_{ij} - r_{ij})\, \hat{\mathbf x}_{ij},
          \qquad k_{ij} = \alpha\, \bar K_{ij}\, \bar s_{ij}^{\,d-2},

the bulk-modulus stiffness of the rigid wall (paper eq. 9 with
:math:`A = s^{d-1}`, :math:`L = s`) using the mean bulk modulus of the pair, so
stiff-soft pairs get a stiffness between the two. The force is
antisymmetric, conserves linear momentum exactly and derives from the
potential :math:`\tfrac12 k (d - r)^2`, so contact is elastic; the energy it
stores is part of ``E_contact``.

Particles added during the run (the debris of eroded elements, born where
the element was, perhaps inside the contact distance of a projectile that
had entered it) keep the overlap they had at birth without force, the
allowance shrinking as they move apart (LS-DYNA's IGNORE): a spring loaded
at birth would release energy that was never stored (kilojoules in the
800 m/s penetration of docs/examples.md).

The model and its tests: docs/theory.md, "Contact between bodies".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, error_model="numpy", parallel=True)
def particle_contact(x, m, size, kbulk, body, tl, dim, offsets, idx, alpha, dist_factor,
                     allow, over, a_contact):
    r"""Add inter-body contact accelerations to ``a_contact`` (N, 3) [m/s^2].

    ``offsets``, ``idx``: a current-configuration neighbour list whose pair
    radius covers ``dist_factor * (s_i + s_j) / 2``; pairs within one body are
    skipped, and so are pairs of two updated-Lagrangian particles (``tl`` (N,)
    bool: total-Lagrangian), which meet through the kernel already (a bar's
    sublayer particles inside the concrete would be pushed out). ``size``
    (N,) particle sizes [m], ``kbulk`` (N,) bulk moduli [Pa], ``body`` (N,)
    body ids. Zero-mass particles take part with no
    force of their own (they carry no momentum) but push their partners.

    ``allow`` (N,) [m]: each particle's overlap allowance (LS-DYNA's IGNORE):
    a pair pushes only by its overlap beyond :math:`\max(a_i, a_j)`,
    :math:`\mathbf f_{ij} = k_{ij} \max(d_{ij} - r_{ij} - \max(a_i, a_j), 0)
    \hat{\mathbf x}_{ij}` (symmetric, so the pair force stays antisymmetric).
    ``over`` (N,) out: each particle's largest raw overlap
    :math:`\max_j (d_{ij} - r_{ij})^+`, with which the caller shrinks the
    allowances. Returns the number of particles in contact (raw overlap).
    """
    n = x.shape[0]
    count = 0
    for i in prange(n):
        bi = body[i]
        tli = tl[i]
        a0 = a1 = a2 = 0.0
        touching = 0
        deepest = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = idx[k]
            if body[j] == bi:
                continue
            if tli == 0 and tl[j] == 0:
                continue
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            sij = 0.5 * (size[i] + size[j])
            dij = dist_factor * sij
            if r2 >= dij * dij or r2 == 0.0:
                continue
            r = np.sqrt(r2)
            touching = 1
            deepest = max(deepest, dij - r)
            pen = dij - r - max(allow[i], allow[j])
            if pen <= 0.0:
                continue
            kij = alpha * 0.5 * (kbulk[i] + kbulk[j]) * sij ** (dim - 2.0)
            f = kij * pen / r
            a0 += f * d0
            a1 += f * d1
            a2 += f * d2
        over[i] = deepest
        if m[i] > 0.0:
            a_contact[i, 0] += a0 / m[i]
            a_contact[i, 1] += a1 / m[i]
            a_contact[i, 2] += a2 / m[i]
        count += touching
    return count


def contact_time_step(m, size, kbulk, dim, alpha, n_contacts=4):
    r"""Stability limit of the contact springs, :math:`2\sqrt{m / (n k)}`.

    A particle may touch up to ``n_contacts`` partners at once; zero-mass
    particles are excluded (they get no contact acceleration).
    """
    ok = m > 0.0
    if not np.any(ok):
        return np.inf
    k = alpha * kbulk[ok] * size[ok] ** (dim - 2.0)
    return float(np.min(2.0 * np.sqrt(m[ok] / (n_contacts * k))))
