"""The total-Lagrangian scheme: reference data built once, two calls per step.

The solver calls :meth:`TotalLagrangian.velocity_gradient` (deformation
gradient, velocity gradient, density ``rho0 / det F``) before the material
update and :meth:`TotalLagrangian.accelerations` (first Piola-Kirchhoff
stress, momentum balance, hourglass control) after it. See
:mod:`sphdyn.sph.total_lagrangian` for the equations.
"""

from __future__ import annotations

import numpy as np

from ..neighbours import build_neighbours
from .total_lagrangian import (deformation_gradient, piola_stress, reference_gradients,
                               tl_forces)


def same_body_pairs(offsets: np.ndarray, idx: np.ndarray, body: np.ndarray):
    """Keep only the CSR pairs whose two particles belong to the same body.

    Returns new ``(offsets, idx)``; rows stay sorted. Used once, so NumPy is
    enough.
    """
    rows = np.repeat(np.arange(offsets.size - 1), np.diff(offsets))
    keep = body[rows] == body[idx]
    counts = np.bincount(rows[keep], minlength=offsets.size - 1)
    new_off = np.zeros(offsets.size, dtype=offsets.dtype)
    np.cumsum(counts, out=new_off[1:])
    return new_off, np.ascontiguousarray(idx[keep])


class TotalLagrangian:
    """Reference neighbours, gradients and work arrays of the particles ``p``.

    Parameters
    ----------
    p : Particles (reference configuration ``p.x0``, ``p.h0``, ``p.rho0``).
    kid, sigma, radius_factor, kscale : kernel id, normalisation, support
        radius factor (q_max * kappa) and support scale kappa.
    young : (N,) Young's modulus per particle for the hourglass stiffness [Pa].
    hourglass : hourglass coefficient alpha (Ganzenmueller 2015; 0 = off).
    """

    def __init__(self, p, kid, sigma, radius_factor, kscale, young, hourglass):
        n, dim = p.n, p.dim
        self.dim = dim
        full = build_neighbours(p.x0, p.h0, radius_factor, 0.0, dim)
        self.offsets, self.idx = same_body_pairs(full.offsets, full.idx, p.body)
        self.vol = np.divide(p.m, p.rho0, out=np.zeros(n), where=p.rho0 > 0)
        self.g = np.zeros((self.idx.size, 3))
        self.w = np.zeros(self.idx.size)
        self.B0 = np.zeros((n, 3, 3))
        reference_gradients(p.x0, p.h0, self.vol, self.offsets, self.idx, kid, sigma,
                            dim, kscale, self.g, self.w, self.B0)
        self.F = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        self.Finv = self.F.copy()
        self.P = np.zeros((n, 3, 3))
        self.young = np.ascontiguousarray(young, dtype=float)
        self.hourglass = float(hourglass)

    def velocity_gradient(self, p) -> None:
        """Fill ``p.L`` and set ``p.rho = rho0 / det F`` for the current state."""
        deformation_gradient(p.x, p.v, self.vol, self.offsets, self.idx, self.g,
                             self.B0, self.dim, self.F, self.Finv, p.L)
        det = np.linalg.det(self.F)
        np.divide(p.rho0, det, out=p.rho, where=det > 0)

    def accelerations(self, p) -> None:
        """Overwrite ``p.a`` with the stress and hourglass accelerations."""
        piola_stress(self.F, self.Finv, p.sig, self.P)
        tl_forces(p.x, p.x0, p.m, p.rho0, self.vol, self.offsets, self.idx, self.g,
                  self.w, self.B0, self.P, self.F, self.young, self.hourglass, p.a)

    @property
    def mean_neighbours(self) -> float:
        return self.idx.size / max(self.offsets.size - 1, 1)
