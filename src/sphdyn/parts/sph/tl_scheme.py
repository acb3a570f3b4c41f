"""The total-Lagrangian scheme: reference data built once, two calls per step.

The SPH part calls :meth:`TotalLagrangian.velocity_gradient` (deformation
gradient, velocity gradient, density ``rho0 / det F``) before the material
update and :meth:`TotalLagrangian.accelerations` (first Piola-Kirchhoff
stress, momentum balance, hourglass control) after it. See
:mod:`sphdyn.parts.sph.total_lagrangian` for the equations.

The model and its tests: docs/theory.md, "Total-Lagrangian SPH".
"""

from __future__ import annotations

import numpy as np

from ...neighbours import build_neighbours
from .total_lagrangian import (deformation_gradient, hourglass_coefficients, piola_stress,
                               reference_gradients, tl_density, tl_forces)


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
    """Reference neighbours, gradients and work arrays of the total-Lagrangian bodies.

    Parameters
    ----------
    p : Particles (initial reference configuration ``p.x0``, ``p.h0``,
        ``p.rho0``).
    rows : (n_tl,) int64, the particles of total-Lagrangian bodies.
    kernel : the kernel context (:class:`sphdyn.kernels.KernelContext`).
    young : (N,) Young's modulus per particle for the hourglass stiffness [Pa].
    hourglass : hourglass coefficient alpha (Ganzenmueller 2015; 0 = off).
    alpha, beta : artificial viscosity coefficients (Monaghan 1992).

    Only pairs of particles within one body and both in ``rows`` are kept;
    rows of other particles are empty, so the arrays are (N, ...) and all
    passes write the ``rows`` only (the zeroed pages of the other rows are
    never touched and take no memory). :meth:`update_reference` makes the current
    configuration the new reference (``X``, ``rho_ref``; the Cauchy stress
    carries over, F restarts from I).

    :meth:`forces_off` takes the pairs of a set of particles among
    themselves out of the momentum equation (viscosity and hourglass
    control included) while the deformation gradient keeps them: the hybrid
    transition layer (:mod:`sphdyn.interactions.hybrid_coupling`), whose
    particles ride with their elements, which carry their stiffness.
    """

    def __init__(self, p, rows, kernel, young, hourglass, alpha=0.0, beta=0.0):
        self.dim = p.dim
        self.rows = np.ascontiguousarray(rows, dtype=np.int64)
        self.kernel = kernel
        self.young = np.ascontiguousarray(young, dtype=float)
        self.hourglass = float(hourglass)
        self.alpha = float(alpha)
        self.beta = float(beta)
        self.n_updates = 0
        self.off = None  # (N,) bool: particles whose mutual pairs carry no force
        self.rebuild(p, p.x0.copy(), p.rho0.copy())

    def rebuild(self, p, X: np.ndarray, rho_ref: np.ndarray) -> None:
        """Reference list, corrected gradients and pair factors for ``X`` (N, 3)."""
        n, dim = p.n, p.dim
        self.X = X
        self.rho_ref = rho_ref
        active = np.zeros(n, dtype=bool)
        active[self.rows] = True
        k = self.kernel
        full = build_neighbours(X, p.h0, k.radius_factor, 0.0, dim, active=active)
        self.offsets, self.idx = same_body_pairs(full.offsets, full.idx, p.body)
        self.vol = np.divide(p.m, rho_ref, out=np.zeros(n), where=rho_ref > 0)
        nnz = self.idx.size
        self.fac = np.zeros(nnz, dtype=np.float32)
        w = np.zeros(nnz)
        # (N, ...) arrays indexed by particle, written only on the rows: the
        # zeroed pages of the other particles are never touched, so they take
        # no memory (a model with a small total-Lagrangian body among many
        # updated-Lagrangian particles, as the drop-weight ram)
        self.B0 = np.zeros((n, 3, 3))
        self.gsum = np.zeros((n, 3))
        reference_gradients(self.rows, X, p.h0, self.vol, self.offsets, self.idx, k.kid,
                            k.sigma, dim, k.support_scale, self.fac, w, self.B0, self.gsum)
        self.F = np.zeros((n, 3, 3))
        self.F[self.rows] = np.eye(3)
        self.Finv = np.zeros((n, 3, 3))
        self.Finv[self.rows] = np.eye(3)
        self.P = np.zeros((n, 3, 3))
        self.Q = np.zeros((n, 3, 3))
        self.hgk = np.zeros(nnz, dtype=np.float32)
        hourglass_coefficients(self.rows, X, self.vol, self.offsets, self.idx, w,
                               self.young, self.hourglass, self.hgk)
        self._force_pairs()

    def forces_off(self, off: np.ndarray) -> None:
        """Take the pairs of two particles of ``off`` (N,) bool out of the forces."""
        self.off = np.asarray(off, dtype=bool)
        self._force_pairs()

    def _force_pairs(self) -> None:
        r"""Pair factors ``fac_f`` and own-share sums ``gsum_f`` of the force pass:
        ``fac`` and ``gsum`` with the pairs of :meth:`forces_off` removed (and
        their hourglass factors zeroed), :math:`\mathbf{gsum}_i = \sum_j V_j
        \mathrm{fac}_{ij}(\mathbf X_i - \mathbf X_j)` over the pairs kept."""
        self.fac_f, self.gsum_f = self.fac, self.gsum
        if self.off is None or not self.off.any():
            return
        if self.off.size != self.X.shape[0]:  # particles were added
            off = np.zeros(self.X.shape[0], dtype=bool)
            k = min(off.size, self.off.size)
            off[:k] = self.off[:k]
            self.off = off
        rows = np.repeat(np.arange(self.offsets.size - 1), np.diff(self.offsets))
        cut = self.off[rows] & self.off[self.idx]
        self.fac_f = self.fac.copy()
        self.fac_f[cut] = 0.0
        self.hgk[cut] = 0.0
        i, j = rows[cut], self.idx[cut]
        share = (self.vol[j] * self.fac[cut].astype(np.float64))[:, None] * (self.X[i] - self.X[j])
        self.gsum_f = np.zeros(self.gsum.shape)  # pages of other rows stay untouched
        self.gsum_f[self.rows] = self.gsum[self.rows]
        np.subtract.at(self.gsum_f, i, share)
        if self.dim == 2:
            self.gsum_f[self.rows, 2] = 0.0

    def update_reference(self, p) -> None:
        """Make the current positions and densities the reference configuration.

        For large deformations (thesis sec. 2.2.1: the Lagrangian kernel
        fails once the reference neighbourhoods are badly distorted): the
        neighbour list, corrected gradients and hourglass factors are rebuilt
        from ``p.x`` with ``rho_ref = p.rho``; the Cauchy stress and history
        stay. Costs one neighbour build.
        """
        self.rebuild(p, p.x.copy(), p.rho.copy())
        self.n_updates += 1

    def velocity_gradient(self, p) -> None:
        """Fill ``p.L`` (and ``F``) of the total-Lagrangian rows."""
        deformation_gradient(self.rows, p.x, p.v, self.X, self.vol, self.offsets,
                             self.idx, self.fac, self.B0, self.dim, self.F, self.Finv, p.L)

    def density(self, p) -> None:
        """``rho = rho_ref / det F`` and ``h = h0`` on the total-Lagrangian rows."""
        tl_density(self.rows, self.F, self.rho_ref, p.h0, p.rho, p.h)

    def accelerations(self, p, dedt_av) -> None:
        """Overwrite ``p.a`` and ``dedt_av`` rows with the TL stress, viscosity
        and hourglass terms."""
        piola_stress(self.rows, self.F, self.Finv, p.sig, self.vol, self.B0, self.P, self.Q)
        tl_forces(self.rows, (p.x, p.v, self.X),
                  (p.m, p.rho, self.rho_ref, p.c, p.h0, self.vol),
                  (self.offsets, self.idx, self.fac_f, self.hgk),
                  (self.P, self.Q, self.B0, self.F, self.gsum_f), self.dim,
                  (self.alpha, self.beta, self.kernel.support_scale), p.a, dedt_av)

    @property
    def mean_neighbours(self) -> float:
        return self.idx.size / max(self.rows.size, 1)
